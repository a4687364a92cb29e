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
  /// On a cache line boundary: a row of 8 voxels is exactly one line.
  alignas(64) Voxel voxels[kBlockVoxels];
  /// Per voxel, 1 + the index of its votes in vote_sets, or 0 when it has none. Votes are kept
  /// apart from the geometry because most voxels never hold one: one in seven to ten on
  /// rendered rooms and scene0470 at 2 cm, so 24 bytes for each of those costs far less than
  /// the 24 bytes of slots every voxel carried before.
  uint16_t vote_slot[kBlockVoxels] = {};
  /// The vote sets of the voxels that hold votes, in the order they got their first vote.
  /// Every set holds at least one vote: a set is only made for a vote (votesToWrite, then
  /// addVotes), and moving votes away refills the slot it empties.
  std::vector<VoxelVotes> vote_sets;

  /// Voxel at local coordinates (x, y, z), each in [0, kBlockSide).
  Voxel& at(int x, int y, int z) { return voxels[linear(x, y, z)]; }
  /// Voxel at local coordinates (x, y, z), each in [0, kBlockSide).
  const Voxel& at(int x, int y, int z) const { return voxels[linear(x, y, z)]; }
  /// Index in voxels[] of local coordinates (x, y, z).
  static int linear(int x, int y, int z) { return x + kBlockSide * (y + kBlockSide * z); }
  /// Index in voxels[] of a voxel of this block.
  int indexOf(const Voxel& voxel) const { return static_cast<int>(&voxel - voxels); }

  /// The votes of voxel i (index in voxels[]), or null when it has none. The pointer is valid
  /// until a voxel of this block gets its first vote (votesToWrite).
  const VoxelVotes* votes(int i) const {
    const uint16_t slot = vote_slot[i];
    return slot ? &vote_sets[slot - 1] : nullptr;
  }
  /// @copydoc votes(int) const
  VoxelVotes* votes(int i) {
    const uint16_t slot = vote_slot[i];
    return slot ? &vote_sets[slot - 1] : nullptr;
  }
  /// The votes of voxel i, given empty slots first when it has none. Not thread-safe for two
  /// voxels of one block: a writer owns the whole block.
  VoxelVotes* votesToWrite(int i) {
    uint16_t& slot = vote_slot[i];
    if (slot == 0) {
      vote_sets.emplace_back();
      slot = static_cast<uint16_t>(vote_sets.size());
    }
    return &vote_sets[slot - 1];
  }
};
static_assert(kBlockVoxels <= 65535, "vote_slot indexes a block's voxels in 16 bits");

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
  /// The votes of the voxel containing p_W, or null when it has none or its block is not
  /// allocated.
  const VoxelVotes* findVotes(const Eigen::Vector3f& p_W) const;
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
  /// Voxels that hold votes (a vote set): those a measured point fell in.
  size_t numVotedVoxels() const;

  /// Renames the label of every vote: label l becomes to[l]. Votes that then name one label in
  /// a voxel are folded into one slot (renameVotes). Every block holding votes is stamped as
  /// changed. Throws Error, changing nothing, when a vote's label has no entry in `to` or
  /// would become <= 0.
  void renameVotes(const std::vector<int32_t>& to);

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
  // The block of the voxel containing p_W (null when not allocated) and, in *voxel, that
  // voxel's index in it.
  const Block* findBlockOfPoint(const Eigen::Vector3f& p_W, int* voxel) const;

  Config config_;
  uint64_t id_;
  std::atomic<uint64_t> change_stamp_{0};
  absl::flat_hash_map<uint64_t, Block*> index_;
  std::vector<std::unique_ptr<Block>> blocks_;
};

}  // namespace panmap
