#include "panmap/sim/internal/boundary_warp.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "panmap/sim/internal/segmenter_random.h"

namespace panmap {
namespace internal {
namespace segmenter {
namespace {

// Control points of one displacement field: two standard normals (du, dv) per grid node.
cv::Mat coarseField(uint64_t seed, int64_t index, int grid_w, int grid_h) {
  cv::Mat field(grid_h, grid_w, CV_32FC2);
  SegmenterRng rng(hashOf({seed, kBoundary, key(index)}));
  for (int r = 0; r < grid_h; ++r) {
    auto* row = field.ptr<cv::Vec2f>(r);
    for (int c = 0; c < grid_w; ++c) {
      row[c][0] = static_cast<float>(rng.normal());
      row[c][1] = static_cast<float>(rng.normal());
    }
  }
  return field;
}

}  // namespace

// The field is cos/sin-blended between two independent fields so it drifts smoothly in time with
// constant variance, and scaled so its mean per-axis displacement is boundary_mean_px, which for
// an isotropic field is the mean displacement normal to any outline.
void warpLabels(const SegmenterNoiseConfig& c, uint64_t seed, int frame, int width, int height,
                const std::vector<int32_t>& in, std::vector<int32_t>& out) {
  const int grid_w = std::max(2, (width + c.boundary_grid_px - 1) / c.boundary_grid_px);
  const int grid_h = std::max(2, (height + c.boundary_grid_px - 1) / c.boundary_grid_px);
  const int64_t period = c.boundary_period_frames;
  const int64_t index = floorDiv(frame, period);
  const double theta = 0.5 * kPi * static_cast<double>(frame - index * period) / period;
  cv::Mat coarse;
  cv::addWeighted(coarseField(seed, index, grid_w, grid_h), std::cos(theta),
                  coarseField(seed, index + 1, grid_w, grid_h), std::sin(theta), 0.0, coarse);
  cv::Mat field;
  cv::resize(coarse, field, cv::Size(width, height), 0.0, 0.0, cv::INTER_CUBIC);
  const double mean_abs = cv::norm(field, cv::NORM_L1) / (2.0 * width * height);
  const float scale = mean_abs > 0.0 ? static_cast<float>(c.boundary_mean_px / mean_abs) : 0.0f;
  out.resize(in.size());
  for (int v = 0; v < height; ++v) {
    const auto* d = field.ptr<cv::Vec2f>(v);
    int32_t* dst = out.data() + static_cast<size_t>(v) * width;
    for (int u = 0; u < width; ++u) {
      const int su = std::min(width - 1, std::max(0, u + cvRound(d[u][0] * scale)));
      const int sv = std::min(height - 1, std::max(0, v + cvRound(d[u][1] * scale)));
      dst[u] = in[static_cast<size_t>(sv) * width + su];
    }
  }
}

}  // namespace segmenter
}  // namespace internal
}  // namespace panmap
