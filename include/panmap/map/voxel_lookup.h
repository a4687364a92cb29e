#pragma once

#include <atomic>
#include <cmath>
#include <type_traits>

#include <Eigen/Core>

#include "panmap/map/tsdf_map.h"

namespace panmap {

/// Finds the voxel containing a world point, remembering the last block: neighbouring pixels
/// of an image mostly fall in the same block, so most lookups skip the hash map. One per
/// thread and per pass (it caches a block pointer). A mutable lookup is for writing: it stamps
/// every block it finds with one TsdfMap::nextChangeStamp() of its own (Block::changed).
template <typename Map>
class VoxelLookupT {
  using BlockPtr = std::conditional_t<std::is_const<Map>::value, const Block*, Block*>;
  using VoxelPtr = std::conditional_t<std::is_const<Map>::value, const Voxel*, Voxel*>;
  using VotesPtr = std::conditional_t<std::is_const<Map>::value, const VoxelVotes*, VoxelVotes*>;

 public:
  /// @param map the TsdfMap (const or not) looked up
  explicit VoxelLookupT(Map& map) : map_(map), inv_voxel_(1.0f / map.voxelSize()) {
    if constexpr (!std::is_const<Map>::value) stamp_ = map.nextChangeStamp();
  }

  /// The voxel containing p_W, or null when its block is not allocated.
  VoxelPtr find(const Eigen::Vector3f& p_W) {
    return findGrid(floorToInt(p_W.x() * inv_voxel_), floorToInt(p_W.y() * inv_voxel_),
                    floorToInt(p_W.z() * inv_voxel_));
  }

  /// The votes of the voxel containing p_W, or null when it has none or its block is not
  /// allocated.
  VotesPtr findVotes(const Eigen::Vector3f& p_W) {
    const VoxelPtr voxel = find(p_W);
    return voxel ? last_->votes(last_->indexOf(*voxel)) : nullptr;
  }

  /// The votes of the voxel with global integer coordinates g, or null when it has none or its
  /// block is not allocated.
  VotesPtr findGridVotes(const Eigen::Vector3i& g) {
    const VoxelPtr voxel = findGrid(g);
    return voxel ? last_->votes(last_->indexOf(*voxel)) : nullptr;
  }

  /// static_cast<int>(std::floor(x)) for |x| < 2^31, without the library call that baseline
  /// x86-64 (no SSE4.1 rounding) makes for std::floor: truncate, then step down below zero.
  static int floorToInt(float x) {
    const int i = static_cast<int>(x);
    return i - (x < static_cast<float>(i) ? 1 : 0);
  }

  /// The voxel with global integer coordinates (gx, gy, gz), or null when its block is not
  /// allocated.
  VoxelPtr findGrid(int gx, int gy, int gz) {
    static_assert(kBlockSide == 8, "shifts assume 8 voxels per block side");
    const BlockPtr block = findBlock(gx >> 3, gy >> 3, gz >> 3);
    last_voxel_ = Eigen::Vector3i(gx, gy, gz);
    return block ? &block->at(gx & 7, gy & 7, gz & 7) : nullptr;
  }

  /// findGrid(g.x(), g.y(), g.z()).
  VoxelPtr findGrid(const Eigen::Vector3i& g) { return findGrid(g.x(), g.y(), g.z()); }

  /// The block with index (bx, by, bz), or null when it is not allocated.
  BlockPtr findBlock(int bx, int by, int bz) {
    if (!valid_ || bx != last_index_.x() || by != last_index_.y() || bz != last_index_.z()) {
      last_index_ = BlockIndex(bx, by, bz);
      last_ = map_.findBlock(last_index_);
      valid_ = true;
      if constexpr (!std::is_const<Map>::value) {
        if (last_) last_->changed.store(stamp_, std::memory_order_relaxed);
      }
    }
    return last_;
  }

  /// 1 / voxel size, as find() scales points by it.
  float inverseVoxelSize() const { return inv_voxel_; }

  /// The block of the voxel of the last find() or findGrid(), null when it is not allocated.
  BlockPtr lastBlock() const { return last_; }

  /// Global integer coordinates of the voxel of the last find().
  const Eigen::Vector3i& lastVoxel() const { return last_voxel_; }

 private:
  Map& map_;
  float inv_voxel_;
  BlockPtr last_ = nullptr;
  BlockIndex last_index_ = BlockIndex::Zero();
  Eigen::Vector3i last_voxel_ = Eigen::Vector3i::Zero();
  bool valid_ = false;
  uint64_t stamp_ = 0;  // mutable lookups: Block::changed of the blocks found
};

/// Read-only lookups.
using VoxelLookup = VoxelLookupT<const TsdfMap>;
/// Lookups that may change the voxels found.
using MutableVoxelLookup = VoxelLookupT<TsdfMap>;

}  // namespace panmap
