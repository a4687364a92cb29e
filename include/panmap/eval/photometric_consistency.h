#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/camera.h"
#include "panmap/core/image.h"
#include "panmap/core/pose.h"

namespace panmap {

/// Settings of the photometric consistency check of a trajectory: each frame's depth pixels
/// are carried into a later frame by the two poses and the colours there are compared. Colour
/// plays no part in depth-based tracking (ours or KinectFusion's), so the figure judges two
/// trajectories of one sequence without trusting either.
struct PhotometricConfig {
  /// Frame pairs (i, i + gap) for each gap, in frames of the sequence as given.
  std::vector<int> frame_gaps = {1, 3, 10, 30};
  int pixel_stride = 4;  ///< every n-th pixel of every n-th row of the first frame
  /// Only pixels whose grey-level gradient (central differences, grey levels per pixel) is at
  /// least this: flat regions do not tell a misaligned pose from a good one.
  double min_gradient = 6.0;
  double max_depth_m = 4.0;  ///< farther depth is too noisy to carry a pixel
  /// A carried point is occluded in the second frame when its depth there differs from the
  /// second frame's own depth by more than this absolute plus relative tolerance.
  double occlusion_tolerance_m = 0.05;
  double occlusion_tolerance_rel = 0.03;
  /// A pair with fewer samples than this is left out (little overlap).
  size_t min_samples = 200;
  /// Throws Error naming the bad field.
  void check() const;
};

/// One frame as the check needs it.
struct PhotometricFrame {
  int64_t utime = 0;
  PinholeCamera camera;
  double depth_scale_m = 0.001;
  DepthImage depth;
  Image<float> grey;  ///< same size as depth, registered to it
};

/// Grey levels of a colour image (ITU-R BT.601 luma).
Image<float> toGrey(const ColorImage& color);

/// The check of one trajectory over a sequence. Residuals are I_a - I_b at each sampled pixel
/// of frame a carried into frame b, minus the pair's median of that difference (an exposure
/// change between the frames shifts every pixel alike).
struct PhotometricResult {
  size_t frames_posed = 0;        ///< frames the trajectory has a pose for
  size_t pairs = 0;               ///< pairs scored (the same for every trajectory)
  size_t samples = 0;             ///< residuals over all pairs
  double median_abs = 0.0;        ///< median |residual| over all samples, grey levels
  double mean_pair_median = 0.0;  ///< mean over pairs of each pair's median |residual|
};

/// Photometric consistency of each trajectory (T_W_C per utime, matched to the frames' utimes
/// within max_time_difference_us) over `frames` (in time order), scored on the same samples:
/// a pair counts when every trajectory poses both frames, and a pixel when every trajectory
/// carries it unoccluded into the second frame. Throws Error when no pair counts.
std::vector<PhotometricResult> photometricConsistency(
    const std::vector<PhotometricFrame>& frames,
    const std::vector<std::vector<StampedPose>>& trajectories, const PhotometricConfig& config,
    int64_t max_time_difference_us = 1000);

}  // namespace panmap
