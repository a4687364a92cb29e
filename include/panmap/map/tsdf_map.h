#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include <absl/container/flat_hash_map.h>
#include <Eigen/Core>

#include "panmap/map/voxel.h"

namespace panmap {

/// Voxels per block side (voxblox-style blocks of 8^3 voxels).
constexpr int kBlockSide = 8;
/// Voxels per block.
constexpr int kBlockVoxels = kBlockSide * kBlockSide * kBlockSide;

/// Integer block coordinates (block corner = index * block size).
using BlockIndex = Eigen::Vector3i;

/// A cube of kBlockSide^3 voxels, x fastest.
struct Block {
  BlockIndex index = BlockIndex::Zero();
  bool updated = false;  ///< changed since the mesher last looked (cleared by the mesher)
  /// Bit s (1..7) set when voxels this block shares with its lower neighbour at
  /// -(s & 1, s >> 1 & 1, s >> 2) changed since the mesher last looked: that neighbour's cubes
  /// read them (the x = 0 face for bit 0 of s, y = 0 for bit 1, z = 0 for bit 2; all named).
  uint8_t lower_changed = 0;
  /// The TsdfMap::nextChangeStamp() of the last pass that wrote its voxels (0: none since it
  /// was allocated or loaded). Scans that keep results per block (graph/surface_scan.h) redo
  /// the blocks whose stamp moved. Atomic: the threads of one pass may stamp the same block.
  std::atomic<uint64_t> changed{0};
  /// On a cache line boundary: a voxel is half a line, so none straddles two and a row of 8
  /// is exactly 4 lines.
  alignas(64) Voxel voxels[kBlockVoxels];

  /// Voxel at local coordinates (x, y, z), each in [0, kBlockSide).
  Voxel& at(int x, int y, int z) { return voxels[x + kBlockSide * (y + kBlockSide * z)]; }
  /// Voxel at local coordinates (x, y, z), each in [0, kBlockSide).
  const Voxel& at(int x, int y, int z) const {
    return voxels[x + kBlockSide * (y + kBlockSide * z)];
  }
};

/// Hashed blocks of voxels: the label-TSDF's storage. Blocks are created on demand and never
/// move in memory, so pointers to them stay valid.
class TsdfMap {
 public:
  /// Map geometry.
  struct Config {
    float voxel_size_m = 0.01f;  ///< voxel edge length, metres (the paper: 1 cm)
    /// Throws Error naming the bad field.
    void check() const;
  };

  /// Throws Error when the config is invalid.
  explicit TsdfMap(const Config& config);
  /// Takes the blocks and the id of `other`, which is left empty with an id of its own.
  TsdfMap(TsdfMap&& other) noexcept;
  /// @copydoc TsdfMap(TsdfMap&&)
  TsdfMap& operator=(TsdfMap&& other) noexcept;

  /// The config the map was built with.
  const Config& config() const { return config_; }
  /// Voxel edge length, metres.
  float voxelSize() const { return config_.voxel_size_m; }
  /// Block edge length, metres.
  float blockSize() const { return config_.voxel_size_m * kBlockSide; }

  /// Block containing a world point.
  BlockIndex blockIndexOf(const Eigen::Vector3f& p_W) const;
  /// The block at an index, or null when it is not allocated.
  Block* findBlock(const BlockIndex& index);
  /// @copydoc findBlock
  const Block* findBlock(const BlockIndex& index) const;
  /// The block at an index, allocated (all voxels unobserved) when missing.
  Block* allocateBlock(const BlockIndex& index);
  /// The voxel containing a world point, or null when its block is not allocated.
  const Voxel* findVoxel(const Eigen::Vector3f& p_W) const;
  /// Centre of voxel (x, y, z) of a block, world frame, metres.
  Eigen::Vector3f voxelCentre(const BlockIndex& block, int x, int y, int z) const;

  /// Number of allocated blocks.
  size_t numBlocks() const { return blocks_.size(); }
  /// Allocated blocks in allocation order (deterministic for a deterministic input).
  const std::vector<std::unique_ptr<Block>>& blocks() const { return blocks_; }
  /// Allocated blocks in allocation order, mutable.
  std::vector<std::unique_ptr<Block>>& blocks() { return blocks_; }
  /// Bytes used by voxel storage and the index.
  size_t memoryBytes() const;

  /// Unique among the maps of this process: results kept per block (graph/surface_scan.h)
  /// belong to one map, and a map built in its place may reuse the old one's address.
  uint64_t id() const { return id_; }
  /// A stamp larger than every one handed out before, for a pass that writes voxels to store
  /// in Block::changed of each block it writes (MutableVoxelLookup and the integrator do).
  uint64_t nextChangeStamp() { return ++change_stamp_; }
  /// Stamps a block as written by a pass of its own (for writers that use neither).
  void markChanged(Block* block) {
    block->changed.store(nextChangeStamp(), std::memory_order_relaxed);
  }

  /// Hash key of a block index (21 bits per axis, two's complement).
  static uint64_t key(const BlockIndex& index) {
    return (static_cast<uint64_t>(index.x() & 0x1FFFFF) << 42) |
           (static_cast<uint64_t>(index.y() & 0x1FFFFF) << 21) |
           static_cast<uint64_t>(index.z() & 0x1FFFFF);
  }

 private:
  Config config_;
  uint64_t id_;
  std::atomic<uint64_t> change_stamp_{0};
  absl::flat_hash_map<uint64_t, Block*> index_;
  std::vector<std::unique_ptr<Block>> blocks_;
};

}  // namespace panmap
