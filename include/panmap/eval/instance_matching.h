#pragma once

#include <cstdint>
#include <map>
#include <vector>

namespace panmap {

/// ScanNet's minimum region size (evaluate_semantic_instance.py opt['min_region_sizes']).
constexpr int64_t kScanNetMinRegionSize = 100;

/// A ground-truth instance: the GT vertices of one (class, instance id) pair, class evaluated,
/// instance id > 0. Instances under the minimum region size are kept (they are ignored as
/// targets but still excuse the predictions overlapping them, as in the script).
struct GtInstance {
  int32_t class_id = 0;
  int32_t instance_id = 0;
  int64_t vert_count = 0;
  /// (index into InstanceMatches::pred, intersection) for predictions of the same class with
  /// intersection > 0, in prediction order.
  std::vector<std::pair<int, int64_t>> matched_pred;
};

/// A predicted instance: all GT vertices whose transferred instance id is `instance_id`,
/// labelled with the majority transferred class of those vertices (ties: smaller class id).
struct PredInstance {
  int32_t class_id = 0;
  int32_t instance_id = 0;
  int64_t vert_count = 0;
  double confidence = 1.0;
  int64_t void_intersection = 0;  ///< vertices on void GT (not an evaluated class + instance)
  /// (index into InstanceMatches::gt, intersection) for GT instances of the same class.
  std::vector<std::pair<int, int64_t>> matched_gt;
};

/// ScanNet's gt2pred / pred2gt association (assign_instances_for_scan) for one scene.
struct InstanceMatches {
  std::vector<GtInstance> gt;      ///< ascending (class, instance id)
  std::vector<PredInstance> pred;  ///< ascending instance id (the script's file order)
  int64_t min_region_size = kScanNetMinRegionSize;
};

/// Builds the association from per-GT-vertex labels (all four arrays equally long). GT
/// instances: evaluated class and instance > 0; everything else is void. Predictions: instance
/// id > 0, majority class in `classes`, at least `min_region_size` vertices (the script skips
/// smaller prediction masks); confidence from `confidences` (instance id -> confidence),
/// default 1. Throws Error naming the array whose length differs.
InstanceMatches associateInstances(const std::vector<int32_t>& gt_semantic,
                                   const std::vector<int32_t>& gt_instance,
                                   const std::vector<int32_t>& pred_semantic,
                                   const std::vector<int32_t>& pred_instance,
                                   const std::map<int32_t, double>& confidences,
                                   const std::vector<int32_t>& classes,
                                   int64_t min_region_size = kScanNetMinRegionSize);

/// Intersection over union of a GT and a predicted instance given their intersection.
double instanceIoU(const GtInstance& gt, const PredInstance& pred, int64_t intersection);

/// Average precision of one class at one IoU threshold.
struct ApResult {
  double ap = 0.0;        ///< NaN when the class has no GT instance (the script's NaN)
  int num_tp = 0;         ///< GT instances matched (IoU > threshold)
  int num_fp = 0;         ///< false positives entering the curve
  int num_fn = 0;         ///< GT instances left unmatched (hard false negatives)
  bool has_gt = false;    ///< some GT instance of the class reaches the minimum region size
  bool has_pred = false;  ///< some prediction of the class
};

/// evaluate_matches of ScanNet's evaluate_semantic_instance.py for one class and threshold:
/// greedy matching with IoU strictly above the threshold, duplicates as false positives at the
/// lower score, unmatched predictions as false positives unless the share of them on void or
/// small GT exceeds the threshold, then the script's precision/recall curve and step
/// integration. `paper_compatible`: a prediction matched to a GT instance is scored at
/// confidence 1 instead of its own (the released scripts' quirk); false positives keep theirs.
/// `visited` carries the script's pred_visited flags across classes for one threshold
/// (size pred.size(), reset by the caller per threshold).
ApResult scanNetAveragePrecision(const InstanceMatches& matches, int32_t class_id, double threshold,
                                 bool paper_compatible, std::vector<bool>* visited);

/// Panoptic quality of one class at one threshold.
struct PqResult {
  double pq = 0.0, sq = 0.0, rq = 0.0;  ///< NaN when undefined (no GT, no pred / no TP for SQ)
  int tp = 0, fp = 0, fn = 0;
  double sum_iou = 0.0;  ///< over true positives
};

/// PQ = sum IoU(TP) / (TP + FP/2 + FN/2), SQ = sum IoU(TP) / TP, RQ = TP / (TP + FP/2 + FN/2)
/// on the same GT and prediction sets as the AP: GT instances of at least the minimum region
/// size, TP = one-to-one pairs with IoU strictly above `threshold` (greedy by IoU, exact for
/// thresholds >= 0.5 where such pairs are unique), FN = unmatched GT, FP = unmatched
/// predictions that overlap no GT above the threshold and whose void/small-GT share is at most
/// the threshold (the AP's rule).
PqResult panopticQuality(const InstanceMatches& matches, int32_t class_id, double threshold);

}  // namespace panmap
