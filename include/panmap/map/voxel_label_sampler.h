#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/camera.h"
#include "panmap/map/voxel.h"
#include "panmap/map/voxel_lookup.h"

namespace panmap {

/// A sample of one image row for VoxelLabelSampler::labelRow(): its column and depth (> 0).
struct RowSample {
  int u;
  float d_m;
};

/// The super-point label (Eq. 2: argmaxLabel through `resolve`) of the voxel a depth pixel's
/// point falls in, for loops over image samples. Neighbouring samples mostly share a voxel,
/// whose label is then found once, so the map and the labels must not change while a sampler
/// is in use. One per thread.
template <typename Resolve>
class VoxelLabelSampler {
 public:
  /// @param T_W_C camera to world; @param resolve maps a stored label to its live one
  VoxelLabelSampler(const TsdfMap& map, const Eigen::Isometry3f& T_W_C, const PinholeCamera& cam,
                    Resolve resolve)
      : lookup_(map),
        T_W_C_(T_W_C),
        fx_(static_cast<float>(cam.fx)),
        fy_(static_cast<float>(cam.fy)),
        cx_(static_cast<float>(cam.cx)),
        cy_(static_cast<float>(cam.cy)),
        resolve_(std::move(resolve)) {}

  /// The label of the voxel that pixel (u, v) at depth d_m (> 0) sees; 0 when that voxel's
  /// block is not allocated or it has no votes.
  int32_t label(int u, int v, float d_m) { return labelOf(lookup_.find(point(u, v, d_m))); }

  /// Global integer coordinates of the voxel the last label() call found.
  const Eigen::Vector3i& lastVoxel() const { return lookup_.lastVoxel(); }

  /// label() of every sample of row v into labels[k], and lastVoxel() after it into
  /// voxels[k] unless voxels is null. All voxels of the row are found and prefetched before
  /// the first label is read: a voxel read mostly misses the cache, and this way the misses
  /// of a row overlap instead of waiting for one another.
  void labelRow(int v, const std::vector<RowSample>& samples, int32_t* labels,
                Eigen::Vector3i* voxels) {
    row_voxels_.resize(samples.size());
    for (size_t k = 0; k < samples.size(); ++k) {
      const Voxel* voxel = lookup_.find(point(samples[k].u, v, samples[k].d_m));
      row_voxels_[k] = voxel;
      if (voxels) voxels[k] = lookup_.lastVoxel();
      if (voxel) {
        // A voxel may straddle two cache lines.
        __builtin_prefetch(voxel);
        __builtin_prefetch(reinterpret_cast<const char*>(voxel + 1) - 1);
      }
    }
    for (size_t k = 0; k < samples.size(); ++k) labels[k] = labelOf(row_voxels_[k]);
  }

 private:
  Eigen::Vector3f point(int u, int v, float d_m) const {
    return T_W_C_ * Eigen::Vector3f((u - cx_) * d_m / fx_, (v - cy_) * d_m / fy_, d_m);
  }

  int32_t labelOf(const Voxel* voxel) {
    if (!voxel) return 0;
    if (voxel != last_voxel_) {
      last_voxel_ = voxel;
      last_label_ = argmaxLabel(*voxel, resolve_);
    }
    return last_label_;
  }

  VoxelLookup lookup_;
  Eigen::Isometry3f T_W_C_;
  float fx_, fy_, cx_, cy_;
  Resolve resolve_;
  const Voxel* last_voxel_ = nullptr;
  int32_t last_label_ = 0;
  std::vector<const Voxel*> row_voxels_;  // scratch of labelRow()
};

}  // namespace panmap
