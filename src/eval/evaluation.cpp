#include "panmap/eval/evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"

namespace panmap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// numpy.nanmean: the mean of the non-NaN values, NaN when there are none.
double nanMean(const std::vector<double>& values) {
  double sum = 0.0;
  int n = 0;
  for (double v : values) {
    if (!std::isnan(v)) sum += v, ++n;
  }
  return n > 0 ? sum / n : kNaN;
}

/// Per-vertex class IoU as ScanNet's evaluate_semantic_label.py: vertices whose GT class is not
/// evaluated are ignored; FP = predicted c on vertices of another evaluated class.
// Per-vertex IoU of class c over the GT vertices of an evaluated class, with its counts.
struct SemanticCounts {
  int64_t tp = 0, fp = 0, fn = 0;
  double iou() const {
    const int64_t denominator = tp + fp + fn;
    return denominator > 0 ? static_cast<double>(tp) / static_cast<double>(denominator) : kNaN;
  }
};

SemanticCounts semanticCounts(const std::vector<int32_t>& gt, const std::vector<int32_t>& pred,
                              const std::vector<int32_t>& classes, int32_t c) {
  SemanticCounts n;
  for (size_t v = 0; v < gt.size(); ++v) {
    if (std::find(classes.begin(), classes.end(), gt[v]) == classes.end()) continue;
    if (gt[v] == c) {
      (pred[v] == c ? n.tp : n.fn) += 1;
    } else if (pred[v] == c) {
      ++n.fp;
    }
  }
  return n;
}

std::string fmt(double v) {
  if (std::isnan(v)) return "    -";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%5.3f", v);
  return buf;
}

}  // namespace

std::vector<double> scanNetApThresholds() {
  std::vector<double> t;
  for (int i = 0; i < 9; ++i) t.push_back(0.5 + i * 0.05);  // as numpy.arange computes them
  return t;
}

std::vector<SuperpointScore> superpointScores(const InstanceMatches& matches,
                                              const std::vector<int32_t>& gt_semantic,
                                              const std::vector<int32_t>& gt_instance,
                                              const std::vector<int32_t>& pred_superpoint) {
  const size_t n = gt_semantic.size();
  if (gt_instance.size() != n || pred_superpoint.size() != n) {
    throw Error("superpointScores: gt_instance / pred_superpoint length differs from gt_semantic");
  }
  std::map<std::pair<int32_t, int32_t>, int> gt_index;
  for (size_t g = 0; g < matches.gt.size(); ++g) {
    gt_index[{matches.gt[g].class_id, matches.gt[g].instance_id}] = static_cast<int>(g);
  }
  std::map<int32_t, int64_t> superpoint_size;
  std::map<std::pair<int, int32_t>, int64_t> intersections;  // (gt, superpoint) -> count
  for (size_t v = 0; v < n; ++v) {
    const int32_t s = pred_superpoint[v];
    if (s == 0) continue;
    ++superpoint_size[s];
    const auto it = gt_index.find({gt_semantic[v], gt_instance[v]});
    if (it != gt_index.end()) ++intersections[{it->second, s}];
  }
  std::vector<SuperpointScore> scores(matches.gt.size());
  for (const auto& [key, inter] : intersections) {
    const int64_t size = superpoint_size.at(key.second);
    const double iou = static_cast<double>(inter) /
                       static_cast<double>(matches.gt[key.first].vert_count + size - inter);
    SuperpointScore& score = scores[key.first];
    if (2 * inter > size) score.sum_iou += iou;
    score.best_iou = std::max(score.best_iou, iou);
  }
  return scores;
}

EvalResult evaluateTransferred(const LabelledMesh& gt, const TransferredLabels& pred,
                               const std::map<int32_t, double>& confidences,
                               const EvalConfig& config) {
  const size_t n = gt.numVertices();
  if (gt.semantic.size() != n) throw Error("evaluate: ground-truth mesh lacks semantic labels");
  if (gt.instance.size() != n) throw Error("evaluate: ground-truth mesh lacks instance labels");
  if (pred.semantic.size() != n || pred.instance.size() != n || pred.superpoint.size() != n) {
    throw Error("evaluate: transferred labels do not match the ground-truth vertex count");
  }
  const std::vector<int32_t>& classes =
      config.classes.empty() ? evaluatedClasses() : config.classes;

  EvalResult result;
  result.paper_compatible = config.paper_compatible;
  result.num_gt_vertices = n;
  result.num_transferred = pred.num_transferred;

  const InstanceMatches matches =
      associateInstances(gt.semantic, gt.instance, pred.semantic, pred.instance, confidences,
                         classes, config.min_region_size);
  const std::vector<SuperpointScore> sp =
      superpointScores(matches, gt.semantic, gt.instance, pred.superpoint);

  // AP per threshold: pred_visited is shared by all classes of one threshold, as in the script.
  std::vector<double> thresholds = scanNetApThresholds();
  thresholds.push_back(0.25);
  std::vector<std::vector<ApResult>> ap(thresholds.size());  // [threshold][class]
  for (size_t t = 0; t < thresholds.size(); ++t) {
    std::vector<bool> visited(matches.pred.size(), false);
    for (int32_t c : classes) {
      ap[t].push_back(
          scanNetAveragePrecision(matches, c, thresholds[t], config.paper_compatible, &visited));
    }
  }
  const size_t t50 = 0, t75 = 5, t25 = thresholds.size() - 1;

  std::vector<double> sp_all;
  for (size_t k = 0; k < classes.size(); ++k) {
    ClassMetrics cm;
    cm.class_id = classes[k];
    std::vector<double> aps;
    for (size_t t = 0; t < t25; ++t) aps.push_back(ap[t][k].ap);
    cm.ap = ap[t50][k].has_gt ? nanMean(aps) : kNaN;
    cm.ap50 = ap[t50][k].ap;
    cm.ap75 = ap[t75][k].ap;
    cm.ap25 = ap[t25][k].ap;
    cm.tp50 = ap[t50][k].num_tp;
    cm.tp75 = ap[t75][k].num_tp;
    const PqResult pq50 = panopticQuality(matches, cm.class_id, 0.5);
    const PqResult pq75 = panopticQuality(matches, cm.class_id, 0.75);
    cm.pq50 = pq50.pq, cm.sq50 = pq50.sq, cm.rq50 = pq50.rq;
    cm.pq75 = pq75.pq, cm.sq75 = pq75.sq, cm.rq75 = pq75.rq;
    std::vector<double> sp_sum, sp_best;
    for (size_t g = 0; g < matches.gt.size(); ++g) {
      const GtInstance& inst = matches.gt[g];
      if (inst.class_id != cm.class_id || inst.vert_count < matches.min_region_size) continue;
      ++cm.num_gt;
      sp_sum.push_back(sp[g].sum_iou);
      sp_best.push_back(sp[g].best_iou);
      sp_all.push_back(sp[g].sum_iou);
    }
    for (const PredInstance& p : matches.pred) cm.num_pred += p.class_id == cm.class_id;
    cm.iou_ls = nanMean(sp_sum);
    cm.iou_ls_best = nanMean(sp_best);
    const SemanticCounts semantic =
        semanticCounts(gt.semantic, pred.semantic, classes, cm.class_id);
    cm.semantic_iou = semantic.iou();
    cm.semantic_gt_vertices = semantic.tp + semantic.fn;
    cm.semantic_false_vertices = semantic.fp;
    result.classes.push_back(cm);
  }

  const auto average = [&](double ClassMetrics::*field) {
    std::vector<double> v;
    for (const ClassMetrics& cm : result.classes) v.push_back(cm.*field);
    return nanMean(v);
  };
  // mAP: nanmean over classes x thresholds 0.5..0.9 (compute_averages' all_ap).
  std::vector<double> all_ap;
  for (size_t t = 0; t < t25; ++t) {
    for (const ApResult& r : ap[t]) all_ap.push_back(r.ap);
  }
  result.map = nanMean(all_ap);
  result.map25 = average(&ClassMetrics::ap25);
  result.map50 = average(&ClassMetrics::ap50);
  result.map75 = average(&ClassMetrics::ap75);
  for (const ClassMetrics& cm : result.classes) {
    result.ntp50 += cm.tp50;
    result.ntp75 += cm.tp75;
  }
  result.pq50 = average(&ClassMetrics::pq50);
  result.sq50 = average(&ClassMetrics::sq50);
  result.rq50 = average(&ClassMetrics::rq50);
  result.pq75 = average(&ClassMetrics::pq75);
  result.sq75 = average(&ClassMetrics::sq75);
  result.rq75 = average(&ClassMetrics::rq75);
  result.iou_ls = average(&ClassMetrics::iou_ls);
  result.iou_ls_best = average(&ClassMetrics::iou_ls_best);
  result.iou_ls_instances = nanMean(sp_all);
  result.miou = average(&ClassMetrics::semantic_iou);
  std::vector<double> present;
  for (const ClassMetrics& cm : result.classes) {
    if (cm.semantic_gt_vertices > 0) {
      present.push_back(cm.semantic_iou);
    } else if (cm.semantic_false_vertices > 0) {
      ++result.spurious_classes;
      result.spurious_vertices += cm.semantic_false_vertices;
    }
  }
  result.miou_gt_classes = nanMean(present);
  return result;
}

EvalResult evaluate(const LabelledMesh& gt, const LabelledMesh& predicted,
                    const std::map<int32_t, double>& confidences, const EvalConfig& config) {
  if (gt.semantic.size() != gt.numVertices()) {
    throw Error("evaluate: ground-truth mesh lacks semantic labels");
  }
  if (gt.instance.size() != gt.numVertices()) {
    throw Error("evaluate: ground-truth mesh lacks instance labels");
  }
  const TransferredLabels pred = transferLabels(predicted, gt.vertices, config.max_distance_m);
  return evaluateTransferred(gt, pred, confidences, config);
}

std::string formatEvalTable(const EvalResult& r) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof(line), "%-16s %4s %4s %5s %5s %5s %5s %4s %4s %5s %5s %5s %5s\n",
                "class", "#gt", "#prd", "AP", "AP50", "AP75", "AP25", "TP50", "TP75", "PQ50",
                "PQ75", "IoULS", "mIoU");
  out += line;
  for (const ClassMetrics& c : r.classes) {
    std::snprintf(line, sizeof(line), "%-16s %4d %4d %s %s %s %s %4d %4d %s %s %s %s\n",
                  nyu40Name(c.class_id).c_str(), c.num_gt, c.num_pred, fmt(c.ap).c_str(),
                  fmt(c.ap50).c_str(), fmt(c.ap75).c_str(), fmt(c.ap25).c_str(), c.tp50, c.tp75,
                  fmt(c.pq50).c_str(), fmt(c.pq75).c_str(), fmt(c.iou_ls).c_str(),
                  fmt(c.semantic_iou).c_str());
    out += line;
  }
  int num_gt = 0, num_pred = 0;
  for (const ClassMetrics& c : r.classes) num_gt += c.num_gt, num_pred += c.num_pred;
  std::snprintf(line, sizeof(line), "%-16s %4d %4d %s %s %s %s %4d %4d %s %s %s %s\n",
                "average/sum", num_gt, num_pred, fmt(r.map).c_str(), fmt(r.map50).c_str(),
                fmt(r.map75).c_str(), fmt(r.map25).c_str(), r.ntp50, r.ntp75, fmt(r.pq50).c_str(),
                fmt(r.pq75).c_str(), fmt(r.iou_ls).c_str(), fmt(r.miou).c_str());
  out += line;
  std::snprintf(line, sizeof(line),
                "SQ50 %s RQ50 %s SQ75 %s RQ75 %s | IoU_LS over instances %s, best-super-point "
                "%s | transferred %zu/%zu GT vertices\n",
                fmt(r.sq50).c_str(), fmt(r.rq50).c_str(), fmt(r.sq75).c_str(), fmt(r.rq75).c_str(),
                fmt(r.iou_ls_instances).c_str(), fmt(r.iou_ls_best).c_str(), r.num_transferred,
                r.num_gt_vertices);
  out += line;
  std::snprintf(line, sizeof(line),
                "mIoU over the GT's classes %s | spurious classes (predicted, absent in GT) %d "
                "on %lld GT vertices\n",
                fmt(r.miou_gt_classes).c_str(), r.spurious_classes,
                static_cast<long long>(r.spurious_vertices));
  out += line;
  if (r.paper_compatible) {
    out +=
        "PAPER-COMPATIBLE: matched predictions scored at confidence 1 (released scripts' "
        "quirk); not the ScanNet benchmark's AP\n";
  }
  return out;
}

}  // namespace panmap
