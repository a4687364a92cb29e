#include "panmap/map/internal/vote_rows.h"

#include <algorithm>
#include <cmath>

#include "panmap/core/cpu_features.h"

namespace panmap {
namespace internal {

namespace {

// Appends n votes for (voxel, label) to the open run, or closes it and opens another: the
// runs n calls with one vote each would give.
inline void addToRun(Block* block, int32_t voxel, int32_t label, VoteRun* run, VoteRun** out,
                     uint32_t n = 1) {
  if (voxel == run->voxel && block == run->block && label == run->label) {
    run->count += n;
    return;
  }
  if (run->count > 0) *(*out)++ = *run;
  *run = VoteRun{block, voxel, label, n};
}

// Pixel (u, v) one at a time: its vote, if it casts one, joins the open run.
inline void votePixel(const Image<float>& depth_m, const LabelImage& labels, int u, int v,
                      const RowGrid& grid, MutableVoxelLookup* lookup, VoteRun* run,
                      VoteRun** out) {
  const int32_t label = labels(u, v);
  const float d = depth_m(u, v);
  if (label <= 0 || d <= 0.0f) return;
  Voxel* voxel = lookup->findGrid(grid.voxel(u, d));
  if (voxel) {
    Block* block = lookup->lastBlock();
    addToRun(block, block->indexOf(*voxel), label, run, out);
  }
}

#ifdef PANMAP_HAVE_AVX2_PATH
// The lane before each lane of x, where lane 0's is lane 7 of the group before: `rotated` is
// x with its lanes rotated up by one (previous_lane: 7, 0, 1, ..., 6), `last_rotated` the same
// of the group before, whose lane 0 is that group's lane 7.
__attribute__((target("avx2"))) inline __m256i laneBefore(__m256i rotated, __m256i last_rotated) {
  return _mm256_blend_epi32(rotated, last_rotated, 1);
}

// Stride 1, eight pixels at a time: RowGrid's chain in AVX2, the same operations in the same
// order (nothing is contracted into FMA), so every pixel lands in the scalar path's voxel.
// Lanes are compared with the lane before on label and grid coordinates; block lookups and
// runs stay scalar, one per stretch of equal voxel and label.
__attribute__((target("avx2"))) size_t findRowVotesAvx2(const Image<float>& depth_m,
                                                        const LabelImage& labels, int v,
                                                        const RowGrid& grid,
                                                        MutableVoxelLookup* lookup, VoteRun* out) {
  VoteRun* const first = out;
  VoteRun run{nullptr, -1, 0, 0};
  const int width = depth_m.width();
  const float* depth_row = &depth_m(0, v);
  const int32_t* label_row = &labels(0, v);
  const __m256 lanes = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256 zero = _mm256_setzero_ps();
  __m256 a[3], b[3], t[3];
  for (int r = 0; r < 3; ++r) {
    a[r] = _mm256_set1_ps(grid.a[r]);
    b[r] = _mm256_set1_ps(grid.b[r]);
    t[r] = _mm256_set1_ps(grid.t[r]);
  }
  alignas(32) int32_t coordinate[3][8];
  const __m256i previous_lane = _mm256_setr_epi32(7, 0, 1, 2, 3, 4, 5, 6);
  // Label and grid coordinates (x, y, z) of the lanes of the last group of eight: lane 0 is
  // compared with the last lane before it, so a stretch that crosses into this group continues
  // the open run without another lookup.
  __m256i last[4] = {};
  // Whether `last` holds the group just before this one and its lane 7 casts a vote; otherwise
  // lane 0, if it votes, starts a stretch.
  bool continues = false;
  // The block of the last stretch looked up (null: not allocated, so it cast no vote).
  Block* last_block = nullptr;
  int u = 0;
  for (; u + 8 <= width; u += 8) {
    const __m256i label = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(label_row + u));
    const __m256 d = _mm256_loadu_ps(depth_row + u);
    const __m256 has_label = _mm256_castsi256_ps(_mm256_cmpgt_epi32(label, _mm256_setzero_si256()));
    int valid = _mm256_movemask_ps(_mm256_and_ps(has_label, _mm256_cmp_ps(d, zero, _CMP_GT_OQ)));
    if (valid == 0) {
      continues = false;
      continue;
    }
    // Integers below 2^24 are exact in float: u + lane is static_cast<float>(u + lane).
    const __m256 uf = _mm256_add_ps(_mm256_set1_ps(static_cast<float>(u)), lanes);
    // Lanes whose label and voxel equal the lane before's.
    const __m256i label_rotated = _mm256_permutevar8x32_epi32(label, previous_lane);
    __m256i same = _mm256_cmpeq_epi32(label, laneBefore(label_rotated, last[0]));
    last[0] = label_rotated;
    for (int r = 0; r < 3; ++r) {
      const __m256 q = _mm256_add_ps(a[r], _mm256_mul_ps(uf, b[r]));
      const __m256 s = _mm256_add_ps(_mm256_mul_ps(d, q), t[r]);
      const __m256i g = _mm256_cvttps_epi32(_mm256_floor_ps(s));
      _mm256_store_si256(reinterpret_cast<__m256i*>(coordinate[r]), g);
      const __m256i g_rotated = _mm256_permutevar8x32_epi32(g, previous_lane);
      same = _mm256_and_si256(same, _mm256_cmpeq_epi32(g, laneBefore(g_rotated, last[1 + r])));
      last[1 + r] = g_rotated;
    }
    static_assert(kBlockSide == 8, "block index and offset assume 8 voxels per block side");
    // One lookup per stretch of voting lanes with the same voxel and label (voxels wider than
    // a pixel make these long), not one per lane. A stretch starts where a voting lane differs
    // from the lane before or follows one that casts no vote, and ends before the next start
    // or non-voting lane; lane 0 continues the last group's lane 7 when both vote and agree.
    const int previous_votes = (valid << 1 | (continues ? 1 : 0)) & 0xFF;
    int starts = ~(_mm256_movemask_ps(_mm256_castsi256_ps(same)) & previous_votes) & valid;
    const int stops = starts | (~valid & 0xFF);
    continues = (valid & 0x80) != 0;
    auto stretchEnd = [stops](int k) {
      const unsigned after = static_cast<unsigned>(stops) & ~((2u << k) - 1);
      return after != 0 ? __builtin_ctz(after) : 8;
    };
    if ((valid & 1) && !(starts & 1) && last_block) {
      // Lane 0 has the voxel and label of the last lane before it: the open run grows.
      run.count += static_cast<uint32_t>(stretchEnd(0));
    }
    for (; starts != 0; starts &= starts - 1) {
      const int k = __builtin_ctz(static_cast<unsigned>(starts));
      const int gx = coordinate[0][k], gy = coordinate[1][k], gz = coordinate[2][k];
      last_block = lookup->findBlock(gx >> 3, gy >> 3, gz >> 3);
      if (last_block) {
        addToRun(last_block, Block::linear(gx & 7, gy & 7, gz & 7), label_row[u + k], &run, &out,
                 static_cast<uint32_t>(stretchEnd(k) - k));
      }
    }
  }
  for (; u < width; ++u) {  // the last pixels of a row not a multiple of 8 wide
    votePixel(depth_m, labels, u, v, grid, lookup, &run, &out);
  }
  if (run.count > 0) *out++ = run;
  return static_cast<size_t>(out - first);
}
#endif

}  // namespace

size_t findRowVotesScalar(const Image<float>& depth_m, const LabelImage& labels, int v, int stride,
                          const Eigen::Isometry3f& T_W_C, const RowCamera& cam,
                          MutableVoxelLookup* lookup, VoteRun* out) {
  VoteRun* const first = out;
  VoteRun run{nullptr, -1, 0, 0};
  const RowGrid grid(T_W_C, cam, lookup->inverseVoxelSize(), v);
  for (int u = 0; u < depth_m.width(); u += stride) {
    votePixel(depth_m, labels, u, v, grid, lookup, &run, &out);
  }
  if (run.count > 0) *out++ = run;
  return static_cast<size_t>(out - first);
}

bool voteRowsUseAvx2() { return cpuHasAvx2(); }

// The block address only spreads the pairs over the table; the sums, found by probing until
// the pair or a free slot, do not depend on it.
size_t sumVoteRuns(VoteRun* runs, size_t n, VoteSumTable* table) {
  // At most half full, so a probe ends soon at a free slot.
  size_t slots = table->stamp.size();
  if (slots < 2 * n || slots == 0) {
    slots = 64;
    while (slots < 2 * n) slots *= 2;
    table->stamp.assign(slots, 0u);
    table->index.assign(slots, 0u);
    table->band = 0;
  }
  ++table->band;
  if (table->band == 0) {  // the stamp wrapped: no slot may look current
    std::fill(table->stamp.begin(), table->stamp.end(), 0u);
    table->band = 1;
  }
  const size_t mask = slots - 1;
  const uint32_t band = table->band;
  uint32_t* stamp = table->stamp.data();
  uint32_t* index = table->index.data();
  size_t m = 0;
  for (size_t i = 0; i < n; ++i) {
    const VoteRun run = runs[i];
    const uint64_t key = (reinterpret_cast<uintptr_t>(run.block) >> 6) ^
                         (static_cast<uint64_t>(run.voxel) << 40) ^
                         (static_cast<uint64_t>(static_cast<uint32_t>(run.label)) << 20);
    size_t h = static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> 32) & mask;
    bool summed = false;
    for (; stamp[h] == band; h = (h + 1) & mask) {
      VoteRun& sum = runs[index[h]];
      if (sum.block == run.block && sum.voxel == run.voxel && sum.label == run.label) {
        sum.count += run.count;
        summed = true;
        break;
      }
    }
    if (summed) continue;
    stamp[h] = band;
    index[h] = static_cast<uint32_t>(m);
    runs[m++] = run;
  }
  return m;
}

size_t findRowVotes(const Image<float>& depth_m, const LabelImage& labels, int v, int stride,
                    const Eigen::Isometry3f& T_W_C, const RowCamera& cam,
                    MutableVoxelLookup* lookup, VoteRun* out) {
#ifdef PANMAP_HAVE_AVX2_PATH
  if (stride == 1 && voteRowsUseAvx2()) {
    return findRowVotesAvx2(depth_m, labels, v, RowGrid(T_W_C, cam, lookup->inverseVoxelSize(), v),
                            lookup, out);
  }
#endif
  return findRowVotesScalar(depth_m, labels, v, stride, T_W_C, cam, lookup, out);
}

}  // namespace internal
}  // namespace panmap
