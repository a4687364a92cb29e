#pragma once

#include <cstddef>

#include <Eigen/Core>

#include "panmap/core/image.h"
#include "panmap/map/tsdf_map.h"

namespace panmap {
namespace internal {

/// What one frame's projective update of a block needs, fixed for the whole frame.
struct BlockUpdateParams {
  const Image<float>* depth_m = nullptr;                ///< depth in metres, 0 = invalid
  const Image<Rgb8>* color = nullptr;                   ///< same size as depth, or null
  float fx = 0, fy = 0, cx = 0, cy = 0;                 ///< pinhole intrinsics, pixels
  Eigen::Matrix3f R_C_W = Eigen::Matrix3f::Identity();  ///< world-to-camera rotation
  float voxel_m = 0.01f;
  float truncation_m = 0.04f;
  float min_depth_m = 0.1f;
  float max_weight = 100.0f;
  bool weight_dropoff = true;
  bool space_carving = false;
};

/// Fuses the frame into every voxel of `block` whose projection sees a surface within the
/// truncation band. origin_C is the centre of the block's voxel (0, 0, 0) in the camera frame.
/// Uses 8-wide AVX2 projection and depth sampling when the CPU has it; the result is bitwise
/// the same as updateBlockScalar's. Returns the number of voxels updated; marks in
/// block->lower_changed the lower neighbours whose cubes read an updated voxel.
size_t updateBlock(const BlockUpdateParams& params, const Eigen::Vector3f& origin_C, Block* block);

/// The reference: one voxel at a time, portable.
size_t updateBlockScalar(const BlockUpdateParams& params, const Eigen::Vector3f& origin_C,
                         Block* block);

/// True when updateBlock runs the AVX2 path on this CPU (AVX2 and F16C).
bool blockUpdateUsesAvx2();

}  // namespace internal
}  // namespace panmap
