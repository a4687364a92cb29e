#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "panmap/core/pose.h"

namespace panmap {

/// Corrected poses of past frames from a SLAM back-end (a loop closure, a pose-graph
/// re-optimisation); the wire form is pose_correction_t. Usually keyframes only.
struct PoseCorrection {
  int64_t utime = 0;               ///< when it was published, microseconds
  int64_t correction_id = 0;       ///< grows with each correction; a newer one supersedes
  std::vector<StampedPose> poses;  ///< corrected T_W_C by frame utime, strictly increasing

  /// Throws Error naming the first problem: no pose, a utime out of order or repeated, a pose
  /// that is not a finite rigid transform.
  void check() const;
};

/// The residual error of a back-end's corrected poses: each keyframe pose is moved by a random
/// rotation and translation of these standard deviations (per axis), from `seed`.
struct CorrectionResidual {
  double sigma_m = 0.0;
  double sigma_rad = 0.0;
  uint64_t seed = 1;
};

/// The correction a SLAM back-end publishes once it closes a loop, for test data: the
/// reference poses of every `every`-th frame (keyframes) and of the last one, each with the
/// residual error given, published a second after the last frame. Throws Error when
/// `reference` is empty or `every` is 0.
PoseCorrection keyframeCorrection(const std::vector<StampedPose>& reference, size_t every,
                                  int64_t correction_id = 1,
                                  const CorrectionResidual& residual = {});

/// What a correction does to a trajectory (the poses frames were integrated with).
struct CorrectedTrajectory {
  std::vector<StampedPose> poses;  ///< every frame of the trajectory, corrected, same order
  /// Corrected utimes that match no frame within the tolerance: named and counted, not used.
  std::vector<int64_t> unknown_utimes;
  int matched = 0;                    ///< corrected utimes that matched a frame
  double max_translation_m = 0.0;     ///< largest move of a camera centre
  double max_rotation_rad = 0.0;      ///< largest change of a camera orientation
  std::vector<double> translation_m;  ///< per frame: how far its camera centre moved
  std::vector<double> rotation_rad;   ///< per frame: how far its orientation turned
};

/// Applies a correction to a trajectory sorted by utime. Each matched frame k gets the world-frame
/// correction D_k = T_new,k T_old,k^-1; a frame between matched frames a and b gets D_a and D_b
/// interpolated by time (linear in translation, slerp in rotation) and applied to its old pose; a
/// frame before the first or after the last matched frame gets that frame's D. Without a matched
/// frame the trajectory is returned unchanged (every utime in unknown_utimes).
/// @param tolerance_us a corrected utime matches the frame nearest in time within this.
CorrectedTrajectory applyCorrection(const std::vector<StampedPose>& trajectory,
                                    const PoseCorrection& correction, int64_t tolerance_us = 0);

/// Why a correction none of whose utimes matched was refused, for a one-line error: "none of
/// its N utimes is a mapped frame (first U, D us from the nearest mapped frame, tolerance T
/// us)", or "(first U, no frame mapped yet)". Says how far off the utimes are, so that a
/// back-end whose timestamps went through a float can be told from one naming other frames.
std::string unmatchedCorrectionReason(const std::vector<StampedPose>& trajectory,
                                      const PoseCorrection& correction, int64_t tolerance_us);

}  // namespace panmap
