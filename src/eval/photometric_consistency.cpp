#include "panmap/eval/photometric_consistency.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "panmap/core/error.h"
#include "panmap/eval/trajectory_error.h"

namespace panmap {
namespace {

/// Bilinear grey level at (u, v); false outside the image's interpolable area.
bool sampleGrey(const Image<float>& grey, double u, double v, float* value) {
  if (!(u >= 0.0 && v >= 0.0 && u < grey.width() - 1 && v < grey.height() - 1)) return false;
  const int u0 = static_cast<int>(u);
  const int v0 = static_cast<int>(v);
  const float fu = static_cast<float>(u - u0);
  const float fv = static_cast<float>(v - v0);
  const float top = (1.0f - fu) * grey(u0, v0) + fu * grey(u0 + 1, v0);
  const float bottom = (1.0f - fu) * grey(u0, v0 + 1) + fu * grey(u0 + 1, v0 + 1);
  *value = (1.0f - fv) * top + fv * bottom;
  return true;
}

float medianOf(std::vector<float> values) {
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

/// Per candidate pixel of a (valid depth, strong gradient; a fixed order), I_a - I_b at the
/// pixel carried into b, or NaN where it leaves b, lands on invalid depth or is occluded.
std::vector<float> pairDifferences(const PhotometricFrame& a, const Eigen::Isometry3d& T_W_A,
                                   const PhotometricFrame& b, const Eigen::Isometry3d& T_W_B,
                                   const PhotometricConfig& config) {
  for (const PhotometricFrame* f : {&a, &b}) {
    if (f->grey.width() != f->depth.width() || f->grey.height() != f->depth.height() ||
        f->depth.width() != f->camera.width || f->depth.height() != f->camera.height) {
      throw Error("photometric check: frame " + std::to_string(f->utime) +
                  ": colour, depth and camera sizes disagree");
    }
  }
  const Eigen::Isometry3d T_B_A = T_W_B.inverse() * T_W_A;
  const double tol_abs = config.occlusion_tolerance_m;
  const double tol_rel = config.occlusion_tolerance_rel;
  const float kMissing = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> differences;
  const int stride = config.pixel_stride;
  for (int v = 1; v < a.depth.height() - 1; v += stride) {
    for (int u = 1; u < a.depth.width() - 1; u += stride) {
      const double z = a.depth(u, v) * a.depth_scale_m;
      if (!(z > 0.0 && z <= config.max_depth_m)) continue;
      const double gu = 0.5 * (a.grey(u + 1, v) - a.grey(u - 1, v));
      const double gv = 0.5 * (a.grey(u, v + 1) - a.grey(u, v - 1));
      if (gu * gu + gv * gv < config.min_gradient * config.min_gradient) continue;
      // From here on every candidate pixel gets a slot, so trajectories compare slot by slot.
      differences.push_back(kMissing);
      const Eigen::Vector3d p_B = T_B_A * a.camera.backProject(u, v, z);
      Eigen::Vector2d uv;
      if (!b.camera.project(p_B, &uv)) continue;
      float grey_b = 0.0f;
      if (!sampleGrey(b.grey, uv.x(), uv.y(), &grey_b)) continue;
      const int ub = static_cast<int>(std::lround(uv.x()));
      const int vb = static_cast<int>(std::lround(uv.y()));
      const double z_b = b.depth(ub, vb) * b.depth_scale_m;
      if (!(z_b > 0.0) || std::abs(z_b - p_B.z()) > tol_abs + tol_rel * p_B.z()) continue;
      differences.back() = a.grey(u, v) - grey_b;
    }
  }
  return differences;
}

}  // namespace

void PhotometricConfig::check() const {
  if (frame_gaps.empty()) throw Error("frame_gaps: give at least one gap");
  for (int gap : frame_gaps) {
    if (gap < 1)
      throw Error("frame_gaps: a gap must be at least 1 frame, got " + std::to_string(gap));
  }
  if (pixel_stride < 1) throw Error("pixel_stride must be at least 1");
  if (!(min_gradient >= 0.0)) throw Error("min_gradient must be >= 0");
  if (!(max_depth_m > 0.0)) throw Error("max_depth_m must be > 0");
  if (!(occlusion_tolerance_m >= 0.0) || !(occlusion_tolerance_rel >= 0.0)) {
    throw Error("occlusion tolerances must be >= 0");
  }
}

Image<float> toGrey(const ColorImage& color) {
  Image<float> grey(color.width(), color.height());
  for (int v = 0; v < color.height(); ++v) {
    for (int u = 0; u < color.width(); ++u) {
      const Rgb8& p = color(u, v);
      grey(u, v) = 0.299f * p.r + 0.587f * p.g + 0.114f * p.b;
    }
  }
  return grey;
}

std::vector<PhotometricResult> photometricConsistency(
    const std::vector<PhotometricFrame>& frames,
    const std::vector<std::vector<StampedPose>>& trajectories, const PhotometricConfig& config,
    int64_t max_time_difference_us) {
  config.check();
  if (trajectories.empty()) throw Error("photometric check: no trajectory given");
  const size_t k = trajectories.size();
  std::vector<StampedPose> stamps(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) stamps[i].utime = frames[i].utime;
  // pose[t][frame]: the pose trajectory t gives the frame, or null.
  std::vector<std::vector<const Eigen::Isometry3d*>> pose(
      k, std::vector<const Eigen::Isometry3d*>(frames.size(), nullptr));
  std::vector<PhotometricResult> results(k);
  for (size_t t = 0; t < k; ++t) {
    for (const auto& [frame, at] :
         associateByTime(stamps, trajectories[t], max_time_difference_us)) {
      pose[t][frame] = &trajectories[t][at].T_W_C;
    }
    results[t].frames_posed = static_cast<size_t>(std::count_if(
        pose[t].begin(), pose[t].end(), [](const Eigen::Isometry3d* p) { return p != nullptr; }));
  }
  const auto posedByAll = [&](size_t frame) {
    for (size_t t = 0; t < k; ++t) {
      if (!pose[t][frame]) return false;
    }
    return true;
  };
  std::vector<std::vector<float>> all(k);
  std::vector<double> pair_median_sum(k, 0.0);
  size_t pairs = 0;
  for (int gap : config.frame_gaps) {
    for (size_t i = 0; i + gap < frames.size(); ++i) {
      const size_t j = i + gap;
      if (!posedByAll(i) || !posedByAll(j)) continue;
      std::vector<std::vector<float>> d(k);
      for (size_t t = 0; t < k; ++t) {
        d[t] = pairDifferences(frames[i], *pose[t][i], frames[j], *pose[t][j], config);
      }
      // Only the pixels every trajectory carries unoccluded into frame j count: a trajectory
      // that loses the hard pixels must not be scored on the easy ones alone.
      std::vector<size_t> common;
      for (size_t s = 0; s < d[0].size(); ++s) {
        bool valid = true;
        for (size_t t = 0; t < k && valid; ++t) valid = !std::isnan(d[t][s]);
        if (valid) common.push_back(s);
      }
      if (common.size() < config.min_samples) continue;
      ++pairs;
      for (size_t t = 0; t < k; ++t) {
        std::vector<float> r;
        r.reserve(common.size());
        for (size_t s : common) r.push_back(d[t][s]);
        const float offset = medianOf(r);
        for (float& x : r) x = std::abs(x - offset);
        pair_median_sum[t] += medianOf(r);
        all[t].insert(all[t].end(), r.begin(), r.end());
      }
    }
  }
  if (pairs == 0) {
    // Sparse sampling alone gets here too (--stride 64 on 640x480 frames): say what is counted.
    throw Error("photometric check: no frame pair that every trajectory poses with " +
                std::to_string(config.min_samples) + " pixels seen in both (" +
                std::to_string(frames.size()) + " frames; a smaller pixel stride samples more)");
  }
  for (size_t t = 0; t < k; ++t) {
    results[t].pairs = pairs;
    results[t].samples = all[t].size();
    results[t].median_abs = medianOf(std::move(all[t]));
    results[t].mean_pair_median = pair_median_sum[t] / pairs;
  }
  return results;
}

}  // namespace panmap
