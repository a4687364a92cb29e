#pragma once

#include <cstdint>
#include <vector>

#include "panmap/sim/segmenter_noise.h"

namespace panmap {
namespace internal {
namespace segmenter {

/// Backward-warps a label image by a smooth random displacement field (nearest neighbour, so no
/// label is invented): outlines move in blobs of about `c.boundary_grid_px`, not as per-pixel
/// salt. The field drifts into an independent one over `c.boundary_period_frames` and its mean
/// per-axis displacement is `c.boundary_mean_px`.
/// @param in labels, row-major, width x height.
/// @param out resized to the size of `in`; receives the warped labels.
void warpLabels(const SegmenterNoiseConfig& c, uint64_t seed, int frame, int width, int height,
                const std::vector<int32_t>& in, std::vector<int32_t>& out);

}  // namespace segmenter
}  // namespace internal
}  // namespace panmap
