// ScanNet's evaluate_semantic_instance.py (assign_instances_for_scan, evaluate_matches)
// re-implemented for one scene given per-GT-vertex labels, plus panoptic quality on the same
// instance sets.
#include "panmap/eval/instance_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "panmap/core/error.h"

namespace panmap {
namespace {

bool contains(const std::vector<int32_t>& classes, int32_t c) {
  return std::find(classes.begin(), classes.end(), c) != classes.end();
}

/// The script's precision/recall construction and step integration:
/// scores sorted ascending, one curve point per unique score (predictions at or above it
/// count as positives), plus the artificial point (recall 0, precision 1); then
/// AP = dot(precision, convolve([r0, r0, r1, ..., r_{n-1}, 0], [-0.5, 0, 0.5], 'valid')).
double integratePrecisionRecall(std::vector<std::pair<double, double>> score_true,
                                int hard_false_negatives) {
  std::sort(score_true.begin(), score_true.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  const size_t num_examples = score_true.size();
  std::vector<double> cumsum(num_examples);
  double running = 0.0;
  for (size_t i = 0; i < num_examples; ++i) cumsum[i] = running += score_true[i].second;
  const double num_true_examples = num_examples > 0 ? cumsum.back() : 0.0;
  std::vector<size_t> unique_indices;
  for (size_t i = 0; i < num_examples; ++i) {
    if (i == 0 || score_true[i].first != score_true[i - 1].first) unique_indices.push_back(i);
  }
  const size_t n = unique_indices.size() + 1;
  std::vector<double> precision(n, 0.0), recall(n, 0.0);
  for (size_t k = 0; k < unique_indices.size(); ++k) {
    const size_t idx = unique_indices[k];
    const double below = idx == 0 ? 0.0 : cumsum[idx - 1];  // y_true_sorted_cumsum[-1] = 0
    const double tp = num_true_examples - below;
    const double fp = static_cast<double>(num_examples - idx) - tp;
    const double fn = below + hard_false_negatives;
    precision[k] = tp / (tp + fp);
    recall[k] = tp / (tp + fn);
  }
  precision[n - 1] = 1.0;  // the artificial first point of the curve
  recall[n - 1] = 0.0;
  // recall_for_conv = [r0, r0, ..., r_{n-1}, 0]; step_i = 0.5 * (rc[i] - rc[i + 2]).
  std::vector<double> rc;
  rc.push_back(recall[0]);
  rc.insert(rc.end(), recall.begin(), recall.end());
  rc.push_back(0.0);
  double ap = 0.0;
  for (size_t i = 0; i < n; ++i) ap += precision[i] * 0.5 * (rc[i] - rc[i + 2]);
  return ap;
}

/// Vertices of an unmatched prediction that the script does not hold against it: on void GT
/// or on GT instances under the minimum region size.
double ignoredShare(const InstanceMatches& m, const PredInstance& pred) {
  int64_t num_ignore = pred.void_intersection;
  for (const auto& [g, inter] : pred.matched_gt) {
    if (m.gt[g].vert_count < m.min_region_size) num_ignore += inter;
  }
  return static_cast<double>(num_ignore) / static_cast<double>(pred.vert_count);
}

bool overlapsSomeGt(const InstanceMatches& m, const PredInstance& pred, double threshold) {
  for (const auto& [g, inter] : pred.matched_gt) {
    if (instanceIoU(m.gt[g], pred, inter) > threshold) return true;
  }
  return false;
}

}  // namespace

double instanceIoU(const GtInstance& gt, const PredInstance& pred, int64_t intersection) {
  return static_cast<double>(intersection) /
         static_cast<double>(gt.vert_count + pred.vert_count - intersection);
}

InstanceMatches associateInstances(const std::vector<int32_t>& gt_semantic,
                                   const std::vector<int32_t>& gt_instance,
                                   const std::vector<int32_t>& pred_semantic,
                                   const std::vector<int32_t>& pred_instance,
                                   const std::map<int32_t, double>& confidences,
                                   const std::vector<int32_t>& classes, int64_t min_region_size) {
  const size_t n = gt_semantic.size();
  if (gt_instance.size() != n) throw Error("associateInstances: gt_instance length differs");
  if (pred_semantic.size() != n) throw Error("associateInstances: pred_semantic length differs");
  if (pred_instance.size() != n) throw Error("associateInstances: pred_instance length differs");

  InstanceMatches m;
  m.min_region_size = min_region_size;

  // GT instances in ascending (class, instance) order, like np.unique over class*1000+k.
  std::map<std::pair<int32_t, int32_t>, int64_t> gt_counts;
  std::vector<bool> is_void(n, true);
  for (size_t v = 0; v < n; ++v) {
    if (gt_instance[v] > 0 && contains(classes, gt_semantic[v])) {
      ++gt_counts[{gt_semantic[v], gt_instance[v]}];
      is_void[v] = false;
    }
  }
  std::map<std::pair<int32_t, int32_t>, int> gt_index;
  for (const auto& [key, count] : gt_counts) {
    gt_index[key] = static_cast<int>(m.gt.size());
    GtInstance g;
    g.class_id = key.first;
    g.instance_id = key.second;
    g.vert_count = count;
    m.gt.push_back(g);
  }

  // Predicted instances: majority class over their vertices.
  std::map<int32_t, std::map<int32_t, int64_t>> pred_class_counts;
  for (size_t v = 0; v < n; ++v) {
    if (pred_instance[v] > 0) ++pred_class_counts[pred_instance[v]][pred_semantic[v]];
  }
  std::map<int32_t, int> pred_index;
  for (const auto& [id, counts] : pred_class_counts) {
    int32_t best_class = 0;
    int64_t best = -1, total = 0;
    for (const auto& [c, count] : counts) {  // ascending class: ties keep the smaller id
      total += count;
      if (count > best) best = count, best_class = c;
    }
    if (!contains(classes, best_class) || total < min_region_size) continue;
    pred_index[id] = static_cast<int>(m.pred.size());
    PredInstance p;
    p.class_id = best_class;
    p.instance_id = id;
    p.vert_count = total;
    const auto it = confidences.find(id);
    p.confidence = it == confidences.end() ? 1.0 : it->second;
    m.pred.push_back(p);
  }

  // Intersections with GT instances of the prediction's class, and with void.
  std::map<std::pair<int, int>, int64_t> intersections;  // (gt, pred) -> count
  for (size_t v = 0; v < n; ++v) {
    const auto pit = pred_index.find(pred_instance[v]);
    if (pit == pred_index.end()) continue;
    PredInstance& p = m.pred[pit->second];
    if (is_void[v]) {
      ++p.void_intersection;
      continue;
    }
    if (gt_semantic[v] != p.class_id) continue;
    ++intersections[{gt_index.at({gt_semantic[v], gt_instance[v]}), pit->second}];
  }
  for (const auto& [key, count] : intersections) {
    m.gt[key.first].matched_pred.emplace_back(key.second, count);
    m.pred[key.second].matched_gt.emplace_back(key.first, count);
  }
  return m;
}

ApResult scanNetAveragePrecision(const InstanceMatches& m, int32_t class_id, double threshold,
                                 bool paper_compatible, std::vector<bool>* visited) {
  if (visited == nullptr || visited->size() != m.pred.size()) {
    throw Error("scanNetAveragePrecision: visited must have one flag per prediction");
  }
  ApResult r;
  std::vector<std::pair<double, double>> score_true;  // (score, 1 = TP / 0 = FP)
  int hard_false_negatives = 0;

  for (const GtInstance& gt : m.gt) {
    if (gt.class_id != class_id || gt.vert_count < m.min_region_size) continue;
    r.has_gt = true;
    bool matched = false;
    double score = -std::numeric_limits<double>::infinity();
    for (const auto& [p, inter] : gt.matched_pred) {
      if ((*visited)[p]) continue;
      const PredInstance& pred = m.pred[p];
      if (!(instanceIoU(gt, pred, inter) > threshold)) continue;
      const double confidence = paper_compatible ? 1.0 : pred.confidence;
      if (matched) {
        // A second prediction for this GT: the lower score becomes a false positive.
        score_true.emplace_back(std::min(score, confidence), 0.0);
        score = std::max(score, confidence);
      } else {
        matched = true;
        score = confidence;
        (*visited)[p] = true;
      }
    }
    if (matched) {
      score_true.emplace_back(score, 1.0);
    } else {
      ++hard_false_negatives;
    }
  }

  for (const PredInstance& pred : m.pred) {
    if (pred.class_id != class_id) continue;
    r.has_pred = true;
    if (overlapsSomeGt(m, pred, threshold)) continue;
    if (ignoredShare(m, pred) <= threshold) score_true.emplace_back(pred.confidence, 0.0);
  }

  for (const auto& st : score_true) (st.second > 0.0 ? r.num_tp : r.num_fp) += 1;
  r.num_fn = hard_false_negatives;
  if (r.has_gt && r.has_pred) {
    r.ap = integratePrecisionRecall(std::move(score_true), hard_false_negatives);
  } else if (r.has_gt) {
    r.ap = 0.0;
  } else {
    r.ap = std::numeric_limits<double>::quiet_NaN();
  }
  return r;
}

PqResult panopticQuality(const InstanceMatches& m, int32_t class_id, double threshold) {
  PqResult r;
  struct Candidate {
    double iou;
    int gt, pred;
  };
  std::vector<Candidate> candidates;
  int num_gt = 0;
  for (size_t g = 0; g < m.gt.size(); ++g) {
    const GtInstance& gt = m.gt[g];
    if (gt.class_id != class_id || gt.vert_count < m.min_region_size) continue;
    ++num_gt;
    for (const auto& [p, inter] : gt.matched_pred) {
      const double iou = instanceIoU(gt, m.pred[p], inter);
      if (iou > threshold) candidates.push_back({iou, static_cast<int>(g), p});
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.iou > b.iou; });
  std::vector<bool> gt_used(m.gt.size(), false), pred_used(m.pred.size(), false);
  for (const Candidate& c : candidates) {
    if (gt_used[c.gt] || pred_used[c.pred]) continue;
    gt_used[c.gt] = pred_used[c.pred] = true;
    ++r.tp;
    r.sum_iou += c.iou;
  }
  r.fn = num_gt - r.tp;
  for (size_t p = 0; p < m.pred.size(); ++p) {
    const PredInstance& pred = m.pred[p];
    if (pred.class_id != class_id || pred_used[p]) continue;
    if (overlapsSomeGt(m, pred, threshold)) continue;
    if (ignoredShare(m, pred) <= threshold) ++r.fp;
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double denominator = r.tp + 0.5 * r.fp + 0.5 * r.fn;
  r.pq = denominator > 0.0 ? r.sum_iou / denominator : nan;
  r.rq = denominator > 0.0 ? r.tp / denominator : nan;
  r.sq = r.tp > 0 ? r.sum_iou / r.tp : nan;
  return r;
}

}  // namespace panmap
