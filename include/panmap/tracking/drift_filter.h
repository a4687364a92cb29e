#pragma once

#include <Eigen/Geometry>

#include "panmap/tracking/pose_increment.h"

namespace panmap {

/// A smooth estimate of a SLAM trajectory's drift: the refined pose is C * T_W_C_slam, with
/// C a rigid correction of the world that changes only as fast as SLAM drift can (a random
/// walk whose variance grows with the distance travelled and the angle turned), estimated by a
/// Kalman filter from per-frame alignments against the map.
///
/// Why: on real depth a frame's alignment against the map disagrees with good poses by about
/// a centimetre and half a degree, correlated over seconds (7-Scenes, docs/MAPPING.md); the
/// SLAM's frame-to-frame motion is better than that, so the filter keeps it as a strong prior
/// and corrects only the slow part of the error. Measured so far it has not beaten
/// frame-by-frame refinement (docs/MAPPING.md, "Real depth"), so it is opt-in.
///
/// The state is C (mean) and its covariance in increment coordinates at the current camera
/// pose (pose_increment.h: world-frame translation, rotation about the camera centre); moving
/// the camera moves the covariance's lever arm. Deterministic; not thread-safe.
class DriftFilter {
 public:
  /// Parameters; units in the names.
  struct Config {
    /// Drift the SLAM input may have: standard deviation of the correction's change per metre
    /// travelled (as a random walk over correlation_m) and per 90 degrees turned. The defaults
    /// cover issue 20's heavy drift (3 %/m, 1.5 deg/m).
    double drift_per_m = 0.03;
    double drift_deg_per_m = 1.5;
    double drift_deg_per_90deg = 1.5;
    /// Distance over which the drift rate stays about the same, metres: the random walk's
    /// variance per metre is drift^2 * correlation_m, so after correlation_m of travel the
    /// standard deviation is drift * correlation_m.
    double correlation_m = 1.0;
    /// Floor of a frame alignment's error, added to its Gauss-Newton covariance (which assumes
    /// independent points and is far too small on real depth).
    double measurement_sigma_m = 0.01;
    double measurement_sigma_deg = 0.5;
    /// Throws Error naming the bad field.
    void check() const;
  };

  /// Throws Error when the config is invalid.
  explicit DriftFilter(const Config& config);

  /// Moves the filter to the next input pose: the covariance grows with the motion since the
  /// last input (nothing on the first call) and its lever arm follows the camera. Returns the
  /// prior refined pose C * T_W_C_input.
  Eigen::Isometry3d predict(const Eigen::Isometry3d& T_W_C_input);

  /// Fuses one alignment of the current frame, made from the pose predict() returned.
  /// @param delta the increment the alignment found (pose_increment.h)
  /// @param information its Gauss-Newton information (AlignmentResult::information)
  /// Returns the refined pose of the current frame.
  Eigen::Isometry3d update(const Vector6d& delta, const Matrix6d& information);

  /// Takes a refined pose of the current frame as it is (no filtering, covariance unchanged):
  /// the correction becomes refined * input^-1. For frame-by-frame refinement.
  Eigen::Isometry3d adopt(const Eigen::Isometry3d& T_W_C_refined);

  /// The correction: refined pose = correction() * input pose.
  const Eigen::Isometry3d& correction() const { return correction_; }
  /// The refined pose of the current frame (after predict(), and update() if called).
  Eigen::Isometry3d current() const { return correction_ * input_; }
  /// Covariance of the correction, increment coordinates at the current camera pose.
  const Matrix6d& covariance() const { return covariance_; }
  /// The config in use.
  const Config& config() const { return config_; }

  /// Everything the filter remembers (for map files).
  struct State {
    bool started = false;
    Eigen::Isometry3d input = Eigen::Isometry3d::Identity();
    Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
    Matrix6d covariance = Matrix6d::Zero();
  };
  /// The filter's state.
  State state() const { return {started_, input_, correction_, covariance_}; }
  /// Continues from a saved state. Throws Error when it is not finite.
  void restore(const State& state);

 private:
  Config config_;
  bool started_ = false;
  Eigen::Isometry3d input_ = Eigen::Isometry3d::Identity();  // the last input pose
  Eigen::Isometry3d correction_ = Eigen::Isometry3d::Identity();
  Matrix6d covariance_ = Matrix6d::Zero();
};

}  // namespace panmap
