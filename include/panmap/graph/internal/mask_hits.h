#pragma once

#include <cstdint>
#include <vector>

#include "panmap/core/frame.h"
#include "panmap/core/image.h"

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

/// The largest mask id a MaskHit can carry (its key is twice the id, plus one when interior).
constexpr int32_t kMaxMaskHitId = kMaxPanopticSegmentId;

/// MaskHit::mask for a pixel of mask `id` (1..kMaxMaskHitId): even near the mask's outline,
/// odd inside it, so that both kinds of one mask sort next to each other.
inline int32_t maskHitKey(int32_t id, bool interior) { return 2 * id + (interior ? 1 : 0); }

/// The mask id of a MaskHit::mask key.
inline int32_t maskOfHitKey(int32_t key) { return key >> 1; }

/// Per pixel 1 for the pixels at least `radius_px` (>= 1) inside their segment's outline, else
/// 0: no pixel within radius_px - 1 (Chebyshev) is an outline pixel, one with a 4-neighbour of
/// another id (pixels outside the image count as the same id). Pixels of id 0 get 0.
void maskInterior(const Image<int32_t>& segment_ids, int radius_px, Image<uint8_t>* interior);

/// The voxel key of a MaskHit for global voxel coordinates (x, y, z).
inline uint64_t maskHitVoxelKey(int x, int y, int z) {
  return (static_cast<uint64_t>(x & 0x1FFFFF) << 42) | (static_cast<uint64_t>(y & 0x1FFFFF) << 21) |
         static_cast<uint64_t>(z & 0x1FFFFF);
}

/// Sorts `hits` by (mask, voxel) and keeps one of each equal pair: the order and the result of
/// std::sort followed by std::unique. `scratch` is working memory (its contents are lost).
void sortUniqueHits(std::vector<MaskHit>* hits, std::vector<MaskHit>* scratch);

}  // namespace panmap::internal
