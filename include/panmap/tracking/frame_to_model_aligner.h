#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/camera.h"
#include "panmap/core/frame.h"
#include "panmap/core/image.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/tracking/pose_increment.h"
#include "panmap/tracking/sdf_residuals.h"

namespace panmap {

/// What became of one alignment.
enum class AlignmentStatus : int8_t {
  kAccepted = 0,        ///< corrected in all six directions
  kAcceptedPartially,   ///< corrected only in the constrained directions (solution remapping)
  kTooFewPoints,        ///< refused: too few depth points fall inside the observed map
  kDegenerate,          ///< refused: unconstrained directions and remapping is off
  kLowInlierRatio,      ///< refused: too few points lie on the model after alignment
  kCorrectionTooLarge,  ///< refused: the correction exceeds what the SLAM pose can be off by
  kSolverFailed,        ///< refused: Ceres reported a failure
};
/// Number of AlignmentStatus values.
constexpr int kAlignmentStatusCount = 7;

/// Image cells across and down of AlignmentResult's per-cell residuals.
constexpr int kResidualCellsX = 8;
constexpr int kResidualCellsY = 6;

/// Short name of a status ("accepted", "too_few_points", ...).
const char* alignmentStatusName(AlignmentStatus status);

/// The outcome of FrameToModelAligner::align().
struct AlignmentResult {
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();  ///< refined, or the prior if refused
  /// True when T_W_C carries a correction (kAccepted or kAcceptedPartially).
  bool accepted = false;
  AlignmentStatus status = AlignmentStatus::kTooFewPoints;
  /// Empty when fully accepted. Otherwise one line: "degenerate: 3 unconstrained directions,
  /// kept at the prior" (kAcceptedPartially), or why the frame was refused: "too few points:
  /// 12 in the map, 300 needed", "degenerate: 3 unconstrained directions", "low inlier ratio:
  /// 0.31 < 0.50", "correction too large: 0.153 m, 0.020 rad", "solver failed: ...".
  std::string reason;
  /// The increment applied to the prior (zero when refused): [dt_W m; dtheta_W rad], see
  /// pose_increment.h; the solution before the acceptance checks is in `solved_delta`.
  Vector6d delta = Vector6d::Zero();
  Vector6d solved_delta = Vector6d::Zero();  ///< what the optimisation found
  int points_selected = 0;                   ///< depth points at the finest level
  /// Of those, on the observed map where the coarser levels left the pose: the finest level's
  /// residuals.
  int points_used = 0;
  double inlier_ratio = 0.0;  ///< share of points_used within inlier_distance_m at the end
  /// Eigenvalues of the normalised, rotation-scaled normal matrix (degeneracy.h), ascending.
  Vector6d eigenvalues = Vector6d::Zero();
  double condition_number = 0.0;  ///< largest / smallest eigenvalue
  int unconstrained_directions = 0;
  /// Gauss-Newton information of the solution (points and prior on the increment) at the end,
  /// increment coordinates: its inverse is the solution's covariance if the points' errors were
  /// independent (on real depth they are not: DriftFilter adds a floor). Zero when refused
  /// before the fit.
  Matrix6d information = Matrix6d::Zero();
  /// Where the frame's depth disagrees with the map after the fit, per image cell (row-major,
  /// kResidualCellsX x kResidualCellsY): sum and count of the inliers' distances along their
  /// rays (SdfResiduals::rayDistances). A fixed pattern across frames is the sensor's depth
  /// error, which the fit cannot remove (DepthPatternMonitor). Empty when refused before the fit.
  std::vector<double> cell_sum_m;
  std::vector<int> cell_count;
  int iterations = 0;    ///< Ceres iterations over all levels
  double time_ms = 0.0;  ///< wall time of align()
};

/// Frame-to-model pose refinement: aligns a depth frame to the TSDF by minimising robust
/// point-to-model distances (the TSDF at each back-projected point, see sdf_residuals.h) plus
/// a prior on the increment to the SLAM pose, with Ceres, coarse to fine over pixel strides
/// (in the manner of Bylow et al., "Real-time camera tracking and 3D reconstruction using
/// signed distance functions", RSS 2013). The correction is accepted only when the points
/// constrain it: directions the normal matrix leaves unconstrained are kept at the prior by
/// solution remapping (Zhang, Kaess and Singh, ICRA 2016: the finest level is solved again
/// within the constrained subspace), or the frame is refused if remapping is off; a low inlier
/// ratio, too few points or an implausibly large correction also keep the SLAM pose.
/// Single-threaded and deterministic: the same inputs give the same bits. One per thread (it
/// counts its outcomes); the map must not change during align().
class FrameToModelAligner {
 public:
  /// Parameters; units in the names.
  struct Config {
    /// Pixel strides of the levels, coarse to fine (the last sets the points used).
    std::vector<int> level_strides_px = {16, 8};
    int max_iterations = 8;  ///< Ceres iterations per level
    RobustLoss loss = RobustLoss::kHuber;
    double robust_scale_m = 0.01;  ///< loss scale, metres
    /// Standard deviation of a point's distance to the model, metres: weighs the points
    /// against the prior.
    double point_sigma_m = 0.01;
    /// Sensor depth noise at 1 m, metres; a point's sigma and loss scale grow with z^2 from
    /// there (SdfResidualOptions::depth_noise_at_1m_m). 0 = every point alike.
    double depth_noise_at_1m_m = 0.0;
    double prior_sigma_translation_m = 0.05;  ///< prior on the increment to the SLAM pose
    double prior_sigma_rotation_rad = 0.05;
    double min_depth_m = 0.1;  ///< depth outside [min, max] is ignored, metres
    double max_depth_m = 3.5;
    int min_points = 300;             ///< points on the map needed at the finest level
    double inlier_distance_m = 0.02;  ///< |sdf| at most this after alignment: an inlier
    double min_inlier_ratio = 0.5;    ///< inliers / in-map points needed
    /// A direction is unconstrained when its eigenvalue is below this share of the largest.
    double min_relative_eigenvalue = 0.01;
    /// Damping of weakly constrained directions, as a share of the strongest direction's
    /// information (0 = off): an extra prior on the increment, isotropic in the
    /// rotation-scaled coordinates of the degeneracy analysis, whose information is this times
    /// the largest eigenvalue of the points' information. A direction with eigenvalue ratio r
    /// then moves r / (r + damping) of the way the points pull it in one frame: directions that
    /// only a few points constrain (a wall's in-plane translations held by its edges) follow the
    /// map over several frames instead of jumping to a biased fit, while well-constrained
    /// directions are barely affected.
    double weak_direction_damping = 0.0;
    /// true: correct the constrained directions only; false: refuse degenerate frames.
    bool remap_degenerate = true;
    double max_correction_translation_m = 0.1;  ///< larger corrections are refused
    double max_correction_rotation_rad = 0.1;
    /// Throws Error naming the bad field.
    void check() const;
    /// The defaults for refining a sequence of SLAM poses frame by frame (the mapper's default,
    /// MapperConfig::PoseCorrection::kPerFrame), where each frame's prior is the previous
    /// refined pose moved by the SLAM relative motion, so the prior is off by the SLAM pose's
    /// frame-to-frame error (millimetres), not by its accumulated drift. Differs from the
    /// single-frame defaults in:
    /// - prior_sigma_translation_m = prior_sigma_rotation_rad = 0.01 (frame-to-frame scale);
    /// - weak_direction_damping = 0.01: weakly constrained directions follow the map over a
    ///   few frames instead of jumping to what a handful of points say.
    /// Measured on the accuracy suite's rooms 3-5 (m2f masks, 2 cm voxels), mean ATE: slam
    /// 2.81 cm -> 0.72 refined (2.90 with the single-frame defaults), slam-hard 8.42 -> 2.01.
    static Config forSequences();
    /// The defaults when each alignment is one measurement of a DriftFilter
    /// (MapperConfig::PoseCorrection::kFilter): the single-frame weak prior (5 cm, 0.05 rad),
    /// no damping (the filter weighs the directions), and strides of 20 then 10 px: about 3,000
    /// points of a 640x480 frame, since the filter gives an alignment no more weight than a
    /// 1 cm / 0.5 deg floor (8 px: 9.6-13 ms instead of 7 ms median on 7-Scenes at 1 cm; ATE
    /// within 1.4 mm).
    static Config forDriftFilter();
  };

  /// Throws Error when the config is invalid.
  explicit FrameToModelAligner(const Config& config);

  /// Aligns a depth frame to the map, starting from (and regularised towards) the SLAM pose.
  /// Throws Error on a non-finite or non-rigid prior, an invalid camera or a depth image whose
  /// size differs from the camera's; a frame that cannot be aligned (empty map, no depth,
  /// degenerate, ...) is refused with a reason and keeps the prior pose.
  /// @param depth depth image in units of depth_scale_m, 0 = no measurement
  /// @param T_W_C_prior camera-to-world pose from SLAM (optical frame)
  AlignmentResult align(const TsdfMap& map, const DepthImage& depth, const PinholeCamera& camera,
                        const Eigen::Isometry3d& T_W_C_prior, double depth_scale_m = 0.001);

  /// align() on a frame's depth, camera and depth scale.
  AlignmentResult align(const TsdfMap& map, const RgbdFrame& frame,
                        const Eigen::Isometry3d& T_W_C_prior) {
    return align(map, frame.depth, frame.camera, T_W_C_prior, frame.depth_scale_m);
  }

  /// Alignments so far by status (index = static_cast<int>(AlignmentStatus)).
  const std::array<int64_t, kAlignmentStatusCount>& counts() const { return counts_; }
  /// The config in use.
  const Config& config() const { return config_; }

 private:
  Config config_;
  std::array<int64_t, kAlignmentStatusCount> counts_{};
};

}  // namespace panmap
