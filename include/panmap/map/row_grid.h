#pragma once

#include <Eigen/Geometry>

#include "panmap/core/camera.h"
#include "panmap/map/voxel_lookup.h"

namespace panmap {

/// Pinhole intrinsics in single precision, pixels: what the per-pixel geometry computes with.
struct RowCamera {
  float fx, fy, cx, cy;

  /// The intrinsics of cam rounded to float.
  static RowCamera of(const PinholeCamera& cam);
};

/// Where the measured points of one image row fall in the voxel grid: the point of pixel u at
/// depth d lies in voxel g = floor(d (a + u b) + t) along each world axis, in voxel units, with
/// a, b and t from the pose, the intrinsics and the row (computed in double, kept in float).
/// One multiply-add chain per axis instead of back-projecting and transforming each point.
/// It is the one definition of "the voxel a pixel sees": label votes are cast in it
/// (internal::findRowVotes, scalar and AVX2 alike), moved from it (vote_split) and read from it
/// (VoxelLabelSampler), so the three always meet in the same voxel.
struct RowGrid {
  /// The constants of row v for the pose T_W_C, intrinsics cam and 1 / voxel size.
  RowGrid(const Eigen::Isometry3f& T_W_C, const RowCamera& cam, float inv_voxel_size, int v);

  /// Grid coordinate along world axis r of pixel u at depth d_m: floor of the float chain
  /// above, in this order (the AVX2 path repeats it exactly; nothing is fused into an FMA).
  int coordinate(int r, int u, float d_m) const {
    const float q = a[r] + static_cast<float>(u) * b[r];
    return VoxelLookup::floorToInt(d_m * q + t[r]);
  }

  /// Global voxel coordinates of pixel u at depth d_m.
  Eigen::Vector3i voxel(int u, float d_m) const {
    return {coordinate(0, u, d_m), coordinate(1, u, d_m), coordinate(2, u, d_m)};
  }

  float a[3], b[3], t[3];
};

}  // namespace panmap
