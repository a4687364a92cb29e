#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/image.h"
#include "panmap/map/row_grid.h"
#include "panmap/map/voxel_lookup.h"

namespace panmap {

/// n consecutive votes of one image row for one voxel and label.
struct VoteRun {
  Block* block;   ///< the voxel's block
  int32_t voxel;  ///< the voxel's index in block->voxels
  int32_t label;
  uint32_t count;
};

namespace internal {

/// Phase 1 of the label votes for image row v: the voxel each labelled pixel's measured point
/// falls in (RowGrid; pixels u = 0, stride, 2 stride, ...), as runs of consecutive votes for one
/// voxel and label (n votes in a row add up exactly as one vote of n does, see addVotes). Pixels
/// without a label, depth or allocated voxel cast no vote. Writes at most width / stride runs
/// to `out` and returns how many. Uses 8-wide AVX2 for stride 1 when the CPU has it, with
/// bitwise the same result as findRowVotesScalar.
size_t findRowVotes(const Image<float>& depth_m, const LabelImage& labels, int v, int stride,
                    const Eigen::Isometry3f& T_W_C, const RowCamera& cam,
                    MutableVoxelLookup* lookup, VoteRun* out);

/// The reference: one pixel at a time through Eigen, portable.
size_t findRowVotesScalar(const Image<float>& depth_m, const LabelImage& labels, int v, int stride,
                          const Eigen::Isometry3f& T_W_C, const RowCamera& cam,
                          MutableVoxelLookup* lookup, VoteRun* out);

/// True when findRowVotes runs the AVX2 path on this CPU.
bool voteRowsUseAvx2();

/// Scratch of sumVoteRuns: which run holds the sum of each (voxel, label) seen in the current
/// band, an open-addressed table at most half full. Reused from band to band without clearing
/// (each slot is stamped with the band that wrote it).
struct VoteSumTable {
  uint32_t band = 0;            ///< stamp of the current band
  std::vector<uint32_t> stamp;  ///< band that wrote each slot (a power of two of them)
  std::vector<uint32_t> index;  ///< the run that slot names
};

/// Sums the runs of one band of rows in place: each run whose voxel and label an earlier run
/// of the band has adds its count to that run and goes, so every pair is left once, where its
/// first run was, and the runs stay in the order found (every voxel sees its first vote where
/// it did). Exact whatever the runs' addresses: the map is the same on every run.
/// Returns how many runs are left, at the front of `runs`.
size_t sumVoteRuns(VoteRun* runs, size_t n, VoteSumTable* table);

}  // namespace internal
}  // namespace panmap
