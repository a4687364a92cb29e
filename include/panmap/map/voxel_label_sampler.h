#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/camera.h"
#include "panmap/map/row_grid.h"
#include "panmap/map/voxel.h"
#include "panmap/map/voxel_lookup.h"

namespace panmap {

/// A sample of one image row for VoxelLabelSampler::labelRow(): its column and depth (> 0).
struct RowSample {
  int u;
  float d_m;
};

/// The super-point label (Eq. 2: argmaxLabel through `resolve`) of the voxel a depth pixel's
/// point falls in (RowGrid: the voxel the pixel votes in), for loops over image samples.
/// Neighbouring samples mostly share a voxel, whose label is then found once, so the map and the
/// labels must not change while a sampler is in use. One per thread.
template <typename Resolve>
class VoxelLabelSampler {
 public:
  /// @param T_W_C camera to world; @param resolve maps a stored label to its live one
  VoxelLabelSampler(const TsdfMap& map, const Eigen::Isometry3f& T_W_C, const PinholeCamera& cam,
                    Resolve resolve)
      : lookup_(map),
        T_W_C_(T_W_C),
        cam_(RowCamera::of(cam)),
        grid_(T_W_C, cam_, lookup_.inverseVoxelSize(), 0),
        resolve_(std::move(resolve)) {}

  /// The label of the voxel that pixel (u, v) at depth d_m (> 0) sees; 0 when that voxel's
  /// block is not allocated or it has no votes.
  int32_t label(int u, int v, float d_m) {
    const RowGrid& grid = row(v);
    return labelOf(lookup_.findGridVotes(grid.voxel(u, d_m)));
  }

  /// The votes of the voxel that pixel (u, v) at depth d_m (> 0) sees; null when its block is
  /// not allocated or it has none.
  const VoxelVotes* votes(int u, int v, float d_m) {
    return lookup_.findGridVotes(row(v).voxel(u, d_m));
  }

  /// Global integer coordinates of the voxel the last label() call found.
  const Eigen::Vector3i& lastVoxel() const { return lookup_.lastVoxel(); }

  /// label() of every sample of row v into labels[k], and lastVoxel() after it into
  /// voxels[k] unless voxels is null. A label is read through two loads that mostly miss the
  /// cache (the voxel's vote slot in its block, then its vote set), so the row goes in three
  /// passes: every voxel found and its slot prefetched, every slot read and its vote set
  /// prefetched, then the labels; the misses of a row overlap instead of waiting in turn.
  void labelRow(int v, const std::vector<RowSample>& samples, int32_t* labels,
                Eigen::Vector3i* voxels) {
    const size_t n = samples.size();
    row_blocks_.resize(n);
    row_index_.resize(n);
    row_votes_.resize(n);
    const RowGrid& grid = row(v);
    for (size_t k = 0; k < n; ++k) {
      const Voxel* voxel = lookup_.findGrid(grid.voxel(samples[k].u, samples[k].d_m));
      if (voxels) voxels[k] = lookup_.lastVoxel();
      const Block* block = voxel ? lookup_.lastBlock() : nullptr;
      row_blocks_[k] = block;
      if (!block) continue;
      row_index_[k] = block->indexOf(*voxel);
      __builtin_prefetch(&block->vote_slot[row_index_[k]]);
    }
    for (size_t k = 0; k < n; ++k) {
      const VoxelVotes* votes = row_blocks_[k] ? row_blocks_[k]->votes(row_index_[k]) : nullptr;
      row_votes_[k] = votes;
      if (votes) {
        // A vote set may straddle two cache lines.
        __builtin_prefetch(votes);
        __builtin_prefetch(reinterpret_cast<const char*>(votes + 1) - 1);
      }
    }
    for (size_t k = 0; k < n; ++k) labels[k] = labelOf(row_votes_[k]);
  }

 private:
  // Row v's grid constants, kept while calls stay on one row.
  const RowGrid& row(int v) {
    if (v != grid_row_) {
      grid_ = RowGrid(T_W_C_, cam_, lookup_.inverseVoxelSize(), v);
      grid_row_ = v;
    }
    return grid_;
  }

  int32_t labelOf(const VoxelVotes* votes) {
    if (!votes) return 0;
    if (votes != last_votes_) {
      last_votes_ = votes;
      last_label_ = argmaxLabel(*votes, resolve_);
    }
    return last_label_;
  }

  VoxelLookup lookup_;
  Eigen::Isometry3f T_W_C_;
  RowCamera cam_;
  RowGrid grid_;
  int grid_row_ = 0;
  Resolve resolve_;
  const VoxelVotes* last_votes_ = nullptr;
  int32_t last_label_ = 0;
  // Scratch of labelRow(): per sample, the voxel's block (null: not allocated), its index
  // there and its votes.
  std::vector<const Block*> row_blocks_;
  std::vector<int> row_index_;
  std::vector<const VoxelVotes*> row_votes_;
};

}  // namespace panmap
