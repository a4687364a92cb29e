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
  /// ATE also fits a constant offset of the camera centre, fixed in the estimate's camera
  /// frame: for two trajectories of different cameras on one rig (a depth camera tracked
  /// against poses of its colour camera), whose centres differ by a lever arm that turns with
  /// the rig and that no rigid alignment of the worlds removes. Changes the ATE only.
  bool fit_camera_offset = false;
  /// ATE aligns by a similarity (rotation, translation and scale) instead of a rigid motion:
  /// for trajectories without metric scale (monocular SLAM, structure from motion). Changes the
  /// ATE only.
  bool fit_scale = false;
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
  /// Alignment applied to the estimate: p_gt ~ T_gt_est * (scale * p_est) (scale 1 unless
  /// fit_scale).
  Eigen::Isometry3d T_gt_est = Eigen::Isometry3d::Identity();
  double scale = 1.0;  ///< fitted with fit_scale, else 1
  /// With fit_camera_offset: the estimate's camera centre to the ground truth's, in the
  /// estimate's camera frame and units (p_gt ~ T_gt_est * (scale * (p_est + R_est * offset)));
  /// else zero.
  Eigen::Vector3d camera_offset_m = Eigen::Vector3d::Zero();
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
/// ||T_gt_est p_est - p_gt||; with fit_scale, Umeyama's similarity; with fit_camera_offset,
/// p_est + R_est * camera_offset_m instead of p_est, the offset and the alignment fitted
/// together (fitAlignment). RPE: for each associated pose i, the associated pose j whose
/// estimate stamp is nearest to t_i + delta (kept when within max_time_difference_s of it),
/// E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) with Q ground truth and P estimate; translation ||t(E)||,
/// rotation the angle of R(E). Unlike evaluate_rpe.py, pairs are not sampled at random and the
/// last pose may end a pair. Throws Error when fewer than 3 poses associate or the config is
/// invalid.
TrajectoryError evaluateTrajectory(const std::vector<StampedPose>& estimate,
                                   const std::vector<StampedPose>& ground_truth,
                                   const TrajectoryErrorConfig& config = TrajectoryErrorConfig());

/// An alignment of an estimated trajectory to a reference: p_gt ~ T (s (p_est + R_est d)).
struct TrajectoryAlignment {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  double scale = 1.0;
  Eigen::Vector3d camera_offset = Eigen::Vector3d::Zero();
};

/// Least squares over T, and s and d where asked: sum_k ||T (s (p_est,k + R_est,k d)) -
/// p_gt,k||^2. Without d, Umeyama's closed form; with d, Gauss-Newton from it (d = 0). Where the
/// estimate's rotations do not excite a direction of d, d and T's translation cannot be told
/// apart there and the least-norm step leaves d at 0. Columns of the matrices are the poses.
TrajectoryAlignment fitAlignment(const std::vector<Eigen::Matrix3d>& R_est,
                                 const Eigen::Matrix3Xd& p_est, const Eigen::Matrix3Xd& p_gt,
                                 bool fit_scale, bool fit_camera_offset);

/// A few lines: associated poses, ATE and RPE statistics ('-' where there were no pairs), and
/// what the alignment fitted besides the rigid motion (scale, camera offset).
std::string formatTrajectoryError(const TrajectoryError& error);

}  // namespace panmap
