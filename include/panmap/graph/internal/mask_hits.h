#pragma once

#include <cstdint>
#include <vector>

namespace panmap::internal {

/// A sampled pixel's mask, the voxel its ray reaches and that voxel's super-point. The voxel is
/// a key of three 21-bit fields (x << 42 | y << 21 | z, each coordinate & 0x1FFFFF).
struct MaskHit {
  uint64_t voxel;
  int32_t mask;
  int32_t label;
  bool operator<(const MaskHit& o) const {
    return mask < o.mask || (mask == o.mask && voxel < o.voxel);
  }
  bool operator==(const MaskHit& o) const { return mask == o.mask && voxel == o.voxel; }
};

/// The voxel key of a MaskHit for global voxel coordinates (x, y, z).
inline uint64_t maskHitVoxelKey(int x, int y, int z) {
  return (static_cast<uint64_t>(x & 0x1FFFFF) << 42) | (static_cast<uint64_t>(y & 0x1FFFFF) << 21) |
         static_cast<uint64_t>(z & 0x1FFFFF);
}

/// Sorts `hits` by (mask, voxel) and keeps one of each equal pair: the order and the result of
/// std::sort followed by std::unique. `scratch` is working memory (its contents are lost).
void sortUniqueHits(std::vector<MaskHit>* hits, std::vector<MaskHit>* scratch);

}  // namespace panmap::internal
