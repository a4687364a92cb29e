#pragma once

#include <cstdint>
#include <vector>

#include "panmap/map/tsdf_map.h"

namespace panmap::internal {

/// The 13 "forward" offsets of the 26-neighbourhood: each touching voxel pair is visited once.
constexpr int kForward[13][3] = {{1, 0, 0},  {0, 1, 0},  {0, 0, 1},  {1, 1, 0},  {1, -1, 0},
                                 {1, 0, 1},  {1, 0, -1}, {0, 1, 1},  {0, 1, -1}, {1, 1, 1},
                                 {1, 1, -1}, {1, -1, 1}, {1, -1, -1}};

/// Surface owners of a block and its 26 neighbours: near[dx + 1][dy + 1][dz + 1] holds
/// kBlockVoxels labels (0: no owner) or is null where no voxel of that block owns surface.
using NearOwners = const std::vector<int32_t>* [3][3][3];

/// Calls pair(label, neighbour) for every surface voxel of the centre block and each forward
/// 26-neighbour (in this block or the next) owned by another super-point.
template <typename Pair>
void forEachTouchingPair(const NearOwners& near, Pair&& pair) {
  const std::vector<int32_t>& labels = *near[1][1][1];
  for (int z = 0; z < kBlockSide; ++z) {
    for (int y = 0; y < kBlockSide; ++y) {
      for (int x = 0; x < kBlockSide; ++x) {
        const int32_t label = labels[static_cast<size_t>(x + kBlockSide * (y + kBlockSide * z))];
        if (label <= 0) continue;
        for (const auto& d : kForward) {
          int nx = x + d[0], ny = y + d[1], nz = z + d[2];
          // Which neighbour block (-1, 0, 1 per axis) and the voxel inside it.
          const int bx = nx < 0 ? -1 : (nx >= kBlockSide ? 1 : 0);
          const int by = ny < 0 ? -1 : (ny >= kBlockSide ? 1 : 0);
          const int bz = nz < 0 ? -1 : (nz >= kBlockSide ? 1 : 0);
          const std::vector<int32_t>* other = near[bx + 1][by + 1][bz + 1];
          if (!other) continue;
          nx -= bx * kBlockSide;
          ny -= by * kBlockSide;
          nz -= bz * kBlockSide;
          const int32_t neighbour =
              (*other)[static_cast<size_t>(nx + kBlockSide * (ny + kBlockSide * nz))];
          if (neighbour > 0 && neighbour != label) pair(label, neighbour);
        }
      }
    }
  }
}

}  // namespace panmap::internal
