#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "panmap/core/labelled_mesh.h"
#include "panmap/eval/instance_matching.h"
#include "panmap/eval/label_transfer.h"

namespace panmap {

/// Settings of the evaluation protocol (DESIGN 8).
struct EvalConfig {
  std::vector<int32_t> classes;  ///< evaluated classes; empty = evaluatedClasses() (ScanNet 18)
  int64_t min_region_size = kScanNetMinRegionSize;    ///< GT and predicted instances smaller
                                                      ///< than this are ignored (ScanNet: 100)
  double max_distance_m = kDefaultTransferDistanceM;  ///< label transfer radius
  /// Score matched predictions at confidence 1 (the released scripts' quirk).
  bool paper_compatible = false;
};

/// The AP thresholds of ScanNet's script: np.arange(0.5, 0.95, 0.05) = 0.5, 0.55, ..., 0.9
/// (nine values; 0.95 is excluded by arange). mAP is their mean.
std::vector<double> scanNetApThresholds();

/// Per-class metrics. NaN marks an undefined value (no GT instance, nothing to average).
struct ClassMetrics {
  int32_t class_id = 0;
  int num_gt = 0;    ///< GT instances of at least the minimum region size
  int num_pred = 0;  ///< predicted instances labelled with the class
  double ap = 0.0;   ///< mean AP over scanNetApThresholds()
  double ap25 = 0.0, ap50 = 0.0, ap75 = 0.0;
  int tp50 = 0, tp75 = 0;
  double pq50 = 0.0, sq50 = 0.0, rq50 = 0.0;
  double pq75 = 0.0, sq75 = 0.0, rq75 = 0.0;
  double iou_ls = 0.0;        ///< super-point IoU_LS averaged over the class's GT instances
  double iou_ls_best = 0.0;   ///< best single super-point IoU averaged likewise
  double semantic_iou = 0.0;  ///< per-vertex class IoU
  /// Evaluated GT vertices of the class (its IoU's true positives and false negatives).
  int64_t semantic_gt_vertices = 0;
  /// Evaluated GT vertices of another class that carry this one (its false positives).
  int64_t semantic_false_vertices = 0;
};

/// Scene metrics: class averages skip NaN classes (numpy nanmean), counts are class sums.
struct EvalResult {
  bool paper_compatible = false;
  size_t num_gt_vertices = 0;
  size_t num_transferred = 0;  ///< GT vertices with a predicted vertex within range
  std::vector<ClassMetrics> classes;
  double map = 0.0, map25 = 0.0, map50 = 0.0, map75 = 0.0;
  int ntp50 = 0, ntp75 = 0;
  double pq50 = 0.0, sq50 = 0.0, rq50 = 0.0;
  double pq75 = 0.0, sq75 = 0.0, rq75 = 0.0;
  double iou_ls = 0.0;            ///< class-averaged (paper tables)
  double iou_ls_instances = 0.0;  ///< the paper's formula: mean over all GT instances
  double iou_ls_best = 0.0;       ///< class-averaged best single super-point IoU
  double miou = 0.0;              ///< semantic mIoU over the evaluated classes
  /// Semantic mIoU over the classes the scene's ground truth has. A class predicted where
  /// the GT has none is left out of it (its vertices still count against the GT's class) and
  /// counted in spurious_classes: in `miou` one such vertex costs a scene of n classes
  /// 1/(n + 1) of its mean, which makes a per-scene figure jump with a handful of vertices.
  double miou_gt_classes = 0.0;
  int spurious_classes = 0;       ///< evaluated classes predicted on GT vertices, absent in GT
  int64_t spurious_vertices = 0;  ///< GT vertices carrying one of those classes
};

/// Super-point accuracy of one GT instance o (our reading of the paper's
/// IoU_LS = 1/|O| sum_o sum_LS IoU(L_S, o)): the sum of IoU(L_S, o) over the super-points
/// L_S with more than half of their vertices inside o (so each super-point counts for at most
/// one instance and the value lies in [0, 1], 1 iff o is exactly a union of super-points).
/// Also returned: the best single super-point IoU.
struct SuperpointScore {
  double sum_iou = 0.0;
  double best_iou = 0.0;
};

/// Super-point scores of every GT instance in `matches` (same order), from per-GT-vertex
/// super-point ids (0 = none, never counted). Throws Error when lengths differ.
std::vector<SuperpointScore> superpointScores(const InstanceMatches& matches,
                                              const std::vector<int32_t>& gt_semantic,
                                              const std::vector<int32_t>& gt_instance,
                                              const std::vector<int32_t>& pred_superpoint);

/// Evaluates transferred labels against the GT mesh (semantic and instance required).
/// @param gt ground-truth mesh
/// @param pred predicted labels per GT vertex (transferLabels)
/// @param confidences predicted instance id -> confidence; missing ids score 1
EvalResult evaluateTransferred(const LabelledMesh& gt, const TransferredLabels& pred,
                               const std::map<int32_t, double>& confidences,
                               const EvalConfig& config = EvalConfig());

/// Label transfer (config.max_distance_m) then evaluateTransferred. Throws Error naming the
/// field when the GT mesh lacks semantic or instance labels.
EvalResult evaluate(const LabelledMesh& gt, const LabelledMesh& predicted,
                    const std::map<int32_t, double>& confidences = {},
                    const EvalConfig& config = EvalConfig());

/// A text table: one row per class, then the averages / sums; marks paper-compatible runs.
std::string formatEvalTable(const EvalResult& result);

}  // namespace panmap
