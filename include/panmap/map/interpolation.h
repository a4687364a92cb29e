#pragma once

#include <Eigen/Core>

#include "panmap/map/tsdf_map.h"

namespace panmap {

/// Trilinear interpolation of the TSDF at a world point, from the 8 voxel centres around it.
/// Returns false when any of them is unobserved (weight 0) or unallocated.
/// @param sdf_m receives the interpolated distance, metres
/// @param gradient_W if not null, receives the interpolated gradient d(sdf)/d(p_W)
bool interpolateSdf(const TsdfMap& map, const Eigen::Vector3f& p_W, float* sdf_m,
                    Eigen::Vector3f* gradient_W = nullptr);

}  // namespace panmap
