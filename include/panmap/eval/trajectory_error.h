#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/pose.h"

namespace panmap {

/// Settings of the trajectory evaluation (TUM RGB-D benchmark, Sturm et al. 2012).
struct TrajectoryErrorConfig {
  /// Estimated and ground-truth poses are associated when their stamps differ by at most this
  /// (TUM's associate.py: 0.02 s).
  double max_time_difference_s = 0.02;
  /// Time between the two poses of a relative pose error (TUM's evaluate_rpe.py --fixed_delta
  /// with --delta 1 --delta_unit s).
  double rpe_delta_s = 1.0;
  /// Throws Error naming the bad field.
  void check() const;
};

/// Summary of a set of errors; all 0 (count 0) when the set is empty.
struct ErrorStats {
  size_t count = 0;
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;  ///< middle value, or the mean of the two middle values
  double max = 0.0;
};

/// Statistics of a list of non-negative errors.
ErrorStats errorStats(std::vector<double> errors);

/// Absolute and relative pose errors of an estimated trajectory against ground truth.
struct TrajectoryError {
  size_t num_estimated = 0;
  size_t num_ground_truth = 0;
  size_t num_associated = 0;  ///< estimated poses with a ground-truth pose in time
  /// Rigid alignment applied to the estimate (no scale): p_gt ~ T_gt_est * p_est.
  Eigen::Isometry3d T_gt_est = Eigen::Isometry3d::Identity();
  ErrorStats ate_m;          ///< ATE: position error after alignment, metres
  ErrorStats rpe_m;          ///< RPE translation over rpe_delta_s, metres
  ErrorStats rpe_deg;        ///< RPE rotation over rpe_delta_s, degrees
  double rpe_delta_s = 1.0;  ///< the delta used
};

/// TUM associate.py: every (estimate, ground truth) pair within max_difference_us, taken
/// greedily by increasing time difference so that each pose is used at most once. Returns
/// (estimate index, ground-truth index) pairs in increasing estimate time. Inputs need not be
/// sorted.
std::vector<std::pair<size_t, size_t>> associateByTime(const std::vector<StampedPose>& estimate,
                                                       const std::vector<StampedPose>& ground_truth,
                                                       int64_t max_difference_us);

/// ATE and RPE (TUM benchmark definitions) of `estimate` against `ground_truth`, both T_W_C
/// (camera to their own world frames).
/// ATE: positions of associated poses aligned by Eigen::umeyama without scale (Horn), error
/// ||T_gt_est p_est - p_gt||. RPE: for each associated pose i, the associated pose j whose
/// estimate stamp is nearest to t_i + delta (kept when within max_time_difference_s of it),
/// E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) with Q ground truth and P estimate; translation ||t(E)||,
/// rotation the angle of R(E). Unlike evaluate_rpe.py, pairs are not sampled at random and the
/// last pose may end a pair. Throws Error when fewer than 3 poses associate or the config is
/// invalid.
TrajectoryError evaluateTrajectory(const std::vector<StampedPose>& estimate,
                                   const std::vector<StampedPose>& ground_truth,
                                   const TrajectoryErrorConfig& config = TrajectoryErrorConfig());

/// A few lines: associated poses, ATE and RPE statistics ('-' where there were no pairs).
std::string formatTrajectoryError(const TrajectoryError& error);

}  // namespace panmap
