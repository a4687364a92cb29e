#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "panmap/map/tsdf_map.h"

namespace panmap {
namespace test {

/// Writes sdf(voxel centre) into every voxel of the blocks overlapping `box` whose distance
/// is within the truncation (weight 1; the others stay unobserved), like a TSDF integrated
/// from a perfect sensor with Euclidean distances.
template <typename Sdf>
void fillAnalyticTsdf(const Eigen::AlignedBox3f& box, float truncation_m, const Sdf& sdf,
                      TsdfMap* map) {
  const BlockIndex lo = map->blockIndexOf(box.min()), hi = map->blockIndexOf(box.max());
  for (int bz = lo.z(); bz <= hi.z(); ++bz) {
    for (int by = lo.y(); by <= hi.y(); ++by) {
      for (int bx = lo.x(); bx <= hi.x(); ++bx) {
        const BlockIndex index(bx, by, bz);
        Block* block = nullptr;
        for (int z = 0; z < kBlockSide; ++z) {
          for (int y = 0; y < kBlockSide; ++y) {
            for (int x = 0; x < kBlockSide; ++x) {
              const float d = sdf(map->voxelCentre(index, x, y, z));
              if (!(std::abs(d) < truncation_m)) continue;
              if (!block) block = map->allocateBlock(index);
              Voxel& voxel = block->at(x, y, z);
              voxel.sdf_m = d;
              voxel.weight = 1.0f;
            }
          }
        }
      }
    }
  }
}

}  // namespace test
}  // namespace panmap
