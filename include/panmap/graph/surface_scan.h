#pragma once

#include <cstdint>
#include <vector>

#include <absl/container/flat_hash_map.h>

#include "panmap/core/thread_pool.h"
#include "panmap/graph/surface_adjacency.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/superpoint/label_registry.h"

namespace panmap {

/// What the super-point graph reads from the whole map (SurfaceAdjacency, its OwnerTotals and
/// which super-points still hold votes), kept per block so that a refresh reads only the blocks
/// that changed since the last one (issue 23: the final optimisation of a building read every
/// voxel, 1.3 s at 2 cm, and so did the pruning every 100 frames). The results equal a full
/// scan's exactly (tests/graph/test_surface_scan.cpp).
///
/// A block is read again when its Block::changed stamp moved (every writer stamps: the
/// integrator and MutableVoxelLookup), when a label of its votes merged into another since in a
/// way that can change an argmax (below), or when a block within one block of it was read again
/// (touching pairs cross block faces). Another map (TsdfMap::id), a registry that shrank or
/// another band starts afresh.
///
/// A merge alone only renames: when no two of a block's roots became one and no root of a voxel
/// that had two roots tied for its argmax was renamed (ties go to the smaller label, which a
/// renaming can change), every voxel keeps its owner under the new name, and the block's
/// summary and its neighbours' touching pairs are renamed without reading a voxel. At the end of
/// the 2 cm building, merges of corridor-long super-points left 20,859 of the 25,711 stale blocks
/// stale by their roots alone.
class SurfaceScan {
 public:
  /// Brings the results up to date with the map and the registry's merges.
  /// @param map the label-TSDF
  /// @param registry the super-point labels (flattened here)
  /// @param band_voxels surface band half-width, in voxels (> 0), as SurfaceAdjacency::compute
  /// @param pool threads to read blocks with (null: the caller's thread); the results do not
  ///        depend on it
  void refresh(const TsdfMap& map, const LabelRegistry& registry, float band_voxels,
               ThreadPool* pool = nullptr);

  /// The surface adjacency, as SurfaceAdjacency::compute gives it for the map at the refresh.
  SurfaceAdjacency adjacency() const;
  /// Adds the owner totals (as SurfaceAdjacency::compute's `totals`) to `totals`, sized by the
  /// caller: labels beyond its size are left out.
  void addTotals(SurfaceAdjacency::OwnerTotals* totals) const;
  /// has[label] = 1 when a vote of the map resolves to the live super-point `label`, indexed up
  /// to the registry's size at the refresh.
  std::vector<uint8_t> hasVotes() const;

  /// Blocks read by the last refresh (all of them the first time).
  size_t blocksRead() const { return last_read_; }
  /// Blocks whose summary the last refresh renamed after merges instead of reading them.
  size_t blocksRenamed() const { return last_renamed_; }
  /// Bytes held by the per-block results.
  size_t memoryBytes() const;

  /// One super-point's share of a block. Voxel-index sums are of in-block coordinates (each
  /// 0..7), so 16 bits hold them: the block's origin is added when the totals are summed.
  struct Owner {
    int32_t label;
    uint16_t voxels;
    uint16_t surface;  ///< of them, in the surface band
    uint16_t index_sum[3];
  };
  /// What one block contributes.
  struct Summary {
    uint64_t changed = 0;         ///< Block::changed when read
    bool read = false;            ///< false: not read yet
    std::vector<int32_t> tied;    ///< roots of the voxels with a tie for the argmax, ascending
    std::vector<int32_t> roots;   ///< distinct roots of its votes, ascending
    std::vector<Owner> owners;    ///< by label, ascending
    std::vector<uint64_t> pairs;  ///< touching pairs with a voxel here (forward offsets)
  };

 private:
  void reset(const TsdfMap& map, float band_voxels);
  void add(const Summary& s, const BlockIndex& index, int sign);
  /// Reads the blocks of `read` (role 2) and the owners of their neighbours (`near_list`,
  /// role 1; `slot`: position -> index into it) and replaces the summaries of `read`.
  void readBlocks(const TsdfMap& map, const std::vector<int32_t>& roots, float band_voxels,
                  const std::vector<size_t>& read, const std::vector<size_t>& near_list,
                  const std::vector<int32_t>& slot, const std::vector<uint8_t>& role,
                  ThreadPool* pool);
  /// The summary with every label replaced by its root (roots: the flattened registry).
  static Summary renamed(const Summary& s, const std::vector<int32_t>& roots);

  uint64_t map_id_ = 0;
  float band_voxels_ = 0.0f;
  double voxel_m_ = 0.0;
  int32_t registry_size_ = -1;
  size_t last_read_ = 0;
  size_t last_renamed_ = 0;
  std::vector<Summary> summaries_;                  // by position in TsdfMap::blocks()
  absl::flat_hash_map<uint64_t, size_t> position_;  // TsdfMap::key -> position
  // Sums over the summaries, by label.
  std::vector<int64_t> voxels_, surface_, vote_blocks_;
  std::vector<Eigen::Matrix<int64_t, 3, 1>> index_sum_;
  absl::flat_hash_map<uint64_t, int> pair_blocks_;  // pair -> summaries holding it
};

}  // namespace panmap
