#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/random.h"

namespace panmap {

/// SLAM-like pose error (DESIGN 10): the estimate integrates the true relative motions with a
/// slowly wandering bias (drift proportional to distance and rotation travelled) plus white
/// per-frame jitter that does not accumulate.
struct PoseDriftConfig {
  std::string preset = "gt";
  /// Standard deviation of the translation drift bias, metres of error per metre travelled.
  double translation_drift_per_m = 0.0;
  /// Standard deviation of the rotation drift bias, degrees per metre travelled.
  double rotation_drift_deg_per_m = 0.0;
  /// Standard deviation of the rotation drift bias, degrees per 90 degrees turned.
  double rotation_drift_deg_per_90deg = 0.0;
  /// Distance over which the bias decorrelates (it is an Ornstein-Uhlenbeck process), metres.
  double bias_correlation_m = 5.0;
  double jitter_translation_m = 0.0;  ///< per-frame white noise, metres (per axis)
  double jitter_rotation_deg = 0.0;   ///< per-frame white noise, degrees (per axis)

  /// Throws Error naming the bad field.
  void check() const;
  /// "gt" (no error), "slam" (ATE RMSE ~3-8 cm over a 2-3 minute room scan), "slam-hard"
  /// (about 3x that), "light" (1 %/m, 0.5 deg/m, 0.5 deg per 90 deg, jitter 1 mm / 0.05 deg)
  /// or "heavy" (3x light), the drift levels injected into recorded real sequences
  /// (docs/SIMULATION.md). Throws Error for other names.
  static PoseDriftConfig fromPreset(const std::string& name);
  /// The preset names fromPreset() knows, comma-separated (for help texts).
  static const char* presetNames();
};

/// The drift model applied one pose at a time, for streams (panmap-import --drift): the
/// poses next() returns are exactly those applyPoseDrift() returns for the same sequence.
class PoseDrift {
 public:
  /// Throws Error when the config is invalid.
  PoseDrift(const PoseDriftConfig& config, uint64_t seed);
  /// The drifting estimate of the next ground-truth pose T_W_C (the first is returned exact).
  Eigen::Isometry3d next(const Eigen::Isometry3d& T_W_C_gt);

 private:
  PoseDriftConfig config_;
  Rng rng_;
  bool started_ = false;
  Eigen::Isometry3d previous_gt_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d estimate_ = Eigen::Isometry3d::Identity();  // drift-free of jitter
  Eigen::Vector3d bias_t_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias_r_dist_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias_r_turn_ = Eigen::Vector3d::Zero();
};

/// The drifting estimate of a ground-truth trajectory T_W_C (one pose per frame). The first
/// pose is exact. Deterministic for a seed.
std::vector<Eigen::Isometry3d> applyPoseDrift(const std::vector<Eigen::Isometry3d>& T_W_C_gt,
                                              const PoseDriftConfig& config, uint64_t seed);

/// Absolute trajectory error: RMSE of camera positions, metres, after the rigid alignment
/// (Umeyama, no scale) of `estimate` onto `reference`. Both must have the same length >= 3.
double absoluteTrajectoryErrorRmse(const std::vector<Eigen::Isometry3d>& estimate,
                                   const std::vector<Eigen::Isometry3d>& reference);

}  // namespace panmap
