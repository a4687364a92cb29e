#pragma once

#include <cstdint>
#include <vector>

#include "panmap/map/tsdf_map.h"
#include "panmap/mesh/marching_cubes.h"

namespace panmap {
namespace internal {

/// The labels of one mesh vertex.
struct VertexLabels {
  int32_t superpoint = 0, semantic = 0, instance = 0;
};

/// Labels vertices from their source voxels through a MeshLabeller, one block's vertices at a
/// time (setBlock). The labels of the voxels around the block are computed once each and kept
/// (a vertex without a label reads its 26 neighbours, which the next vertices mostly share),
/// and so are the last vertex's labels: neighbouring vertices mostly share their voxel, and
/// neighbouring voxels their super-point. The map must not change while it is in use. Used by
/// MeshWelder and BlockMeshLabeller.
class VertexLabeller {
 public:
  /// @param map the map whose voxels label the vertices; must outlive this
  /// @param labeller how voxels are labelled; must outlive this
  VertexLabeller(const TsdfMap& map, const MeshLabeller& labeller)
      : map_(map), labeller_(labeller), region_(kRegionVoxels) {}

  /// Makes `index` the block whose cubes made the next vertices.
  void setBlock(const BlockIndex& index) {
    index_ = index;
    fetched_ = 0;
    if (++stamp_ == 0) {  // wrapped: forget every entry explicitly once
      for (Entry& e : region_) e.stamp = e.fill_stamp = 0;
      stamp_ = 1;
    }
    last_voxel_ = nullptr;
  }

  /// Starts loading the vote slot of a source's voxel, the first of two loads each vertex's
  /// labels wait for; call for a block's vertices before prefetchVotes() and the labels.
  /// @param source a BlockMesh source of the block last given to setBlock()
  void prefetchSlot(uint16_t source) {
    const int local = source & 511;
    if (const Block* b = sourceBlock(source)) __builtin_prefetch(&b->vote_slot[local]);
  }
  /// Starts loading the votes of a source's voxel (its slot should have arrived by now).
  /// @param source a BlockMesh source of the block last given to setBlock()
  void prefetchVotes(uint16_t source) {
    const Block* b = sourceBlock(source);
    if (!b) return;
    if (const VoxelVotes* votes = b->votes(source & 511)) {
      // A vote set may straddle two cache lines (as VoxelLabelSampler::labelRow fetches them).
      __builtin_prefetch(votes);
      __builtin_prefetch(reinterpret_cast<const char*>(votes + 1) - 1);
    }
  }

  /// @param source a BlockMesh source of the block last given to setBlock()
  VertexLabels operator()(uint16_t source) {
    const int local = source & 511;
    int x, y, z;
    decode(source, &x, &y, &z);
    const Block* owner = blockAt(x, y, z);
    if (!owner) return VertexLabels{};
    const Voxel* voxel = &owner->voxels[local];
    if (voxel == last_voxel_) return last_;
    last_voxel_ = voxel;
    const int r = regionIndex(x, y, z);
    const int32_t superpoint = entry(r, x, y, z).label;
    // A filled vertex takes its class and instance from the neighbours' super-point but keeps
    // super-point 0: it belongs to none (super-point diagnostics measure them as voted).
    int32_t source_label = superpoint;
    if (superpoint == 0 && labeller_.fill_from_neighbours) source_label = filledLabel(r, x, y, z);
    if (have_last_ && superpoint == last_.superpoint && source_label == last_source_) {
      return last_;
    }
    have_last_ = true;
    last_source_ = source_label;
    last_.superpoint = superpoint;
    last_.semantic = labeller_.semantic ? labeller_.semantic(source_label) : 0;
    last_.instance = labeller_.instance ? labeller_.instance(source_label) : 0;
    return last_;
  }

 private:
  // The region holds the voxels at block-local coordinates -1 .. 9: sources lie in 0 .. 8.
  static constexpr int kRegionSide = kBlockSide + 3;
  static constexpr int kRegionVoxels = kRegionSide * kRegionSide * kRegionSide;

  struct Entry {
    uint32_t stamp = 0;       // valid when equal to stamp_
    int32_t label = 0;        // super-point, 0 for none or no block
    uint64_t votes = 0;       // all votes of the voxel
    uint32_t fill_stamp = 0;  // `fill` valid when equal to stamp_
    int32_t fill = 0;         // neighbourhoodLabel() of the voxel
  };

  // A source's voxel in coordinates local to the block of setBlock() (0 .. 15).
  static void decode(uint16_t source, int* x, int* y, int* z) {
    const int slot = source >> 9, local = source & 511;
    *x = (slot & 1) * kBlockSide + (local & 7);
    *y = ((slot >> 1) & 1) * kBlockSide + ((local >> 3) & 7);
    *z = (slot >> 2) * kBlockSide + (local >> 6);
  }

  // The block holding a source's voxel.
  const Block* sourceBlock(uint16_t source) {
    int x, y, z;
    decode(source, &x, &y, &z);
    return blockAt(x, y, z);
  }

  static int regionIndex(int x, int y, int z) {
    return (x + 1) + kRegionSide * ((y + 1) + kRegionSide * (z + 1));
  }

  // The block holding block-local (x, y, z), looked up once per setBlock() (most vertices
  // need only a few of the 27). Arithmetic shifts: -1 >> 3 is -1, so -1 .. 9 map to -1 .. 1.
  const Block* blockAt(int x, int y, int z) {
    const int dx = x >> 3, dy = y >> 3, dz = z >> 3;
    const int slot = (dx + 1) + 3 * ((dy + 1) + 3 * (dz + 1));
    if (!(fetched_ >> slot & 1u)) {
      blocks_[slot] = map_.findBlock(index_ + BlockIndex(dx, dy, dz));
      fetched_ |= 1u << slot;
    }
    return blocks_[slot];
  }

  // The labels of the voxel at block-local (x, y, z), region index r.
  const Entry& entry(int r, int x, int y, int z) {
    Entry& e = region_[r];
    if (e.stamp == stamp_) return e;
    e.stamp = stamp_;
    e.label = 0;
    e.votes = 0;
    const Block* b = blockAt(x, y, z);
    if (!b) return e;
    const VoxelVotes* votes = b->votes(Block::linear(x & 7, y & 7, z & 7));
    if (!votes) return e;
    e.votes = votes->total();
    // Voxels without a vote have label 0 without asking.
    if (e.votes > 0) e.label = labeller_.superpoint(*votes);
    return e;
  }

  // neighbourhoodLabel() of the voxel at block-local (x, y, z), region index r, computed once
  // per block: the up to 6 vertices (one per grid edge at the voxel) that take their label from
  // a voxel rarely come one after another.
  int32_t filledLabel(int r, int x, int y, int z) {
    Entry& e = region_[r];
    if (e.fill_stamp != stamp_) {
      e.fill = neighbourhoodLabel(x, y, z);
      e.fill_stamp = stamp_;
    }
    return e.fill;
  }

  // The label most of the 26 neighbours of the voxel at block-local (x, y, z) carry (ties:
  // more votes, then the smaller label); 0 when none carries one.
  int32_t neighbourhoodLabel(int x, int y, int z) {
    struct Tally {
      int32_t label;
      int voxels;
      uint64_t votes;
    };
    Tally tally[26];
    int n = 0;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const int nx = x + dx, ny = y + dy, nz = z + dz;
          const Entry& e = entry(regionIndex(nx, ny, nz), nx, ny, nz);
          if (e.label == 0) continue;
          int k = 0;
          while (k < n && tally[k].label != e.label) ++k;
          if (k == n) tally[n++] = Tally{e.label, 0, 0};
          ++tally[k].voxels;
          tally[k].votes += e.votes;
        }
      }
    }
    int32_t best = 0;
    int best_voxels = 0;
    uint64_t best_votes = 0;
    for (int k = 0; k < n; ++k) {
      const Tally& t = tally[k];
      if (t.voxels > best_voxels || (t.voxels == best_voxels && t.votes > best_votes) ||
          (t.voxels == best_voxels && t.votes == best_votes && t.label < best)) {
        best = t.label, best_voxels = t.voxels, best_votes = t.votes;
      }
    }
    return best;
  }

  const TsdfMap& map_;
  const MeshLabeller& labeller_;
  BlockIndex index_ = BlockIndex::Zero();  // the block of setBlock()
  const Block* blocks_[27] = {};           // it and its 26 neighbours, where fetched_ says
  uint32_t fetched_ = 0;
  std::vector<Entry> region_;
  uint32_t stamp_ = 0;
  const Voxel* last_voxel_ = nullptr;
  bool have_last_ = false;
  int32_t last_source_ = 0;  // the label last_'s class and instance come from
  VertexLabels last_;
};

}  // namespace internal
}  // namespace panmap
