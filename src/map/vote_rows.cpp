#include "panmap/map/internal/vote_rows.h"

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

// Pixel (u, v) one at a time through Eigen: its vote, if it casts one, joins the open run.
inline void votePixel(const Image<float>& depth_m, const LabelImage& labels, int u, int v,
                      const Eigen::Isometry3f& T_W_C, const RowCamera& cam,
                      MutableVoxelLookup* lookup, VoteRun* run, VoteRun** out) {
  const int32_t label = labels(u, v);
  const float d = depth_m(u, v);
  if (label <= 0 || d <= 0.0f) return;
  Voxel* voxel = lookup->find(
      T_W_C * Eigen::Vector3f((u - cam.cx) * d / cam.fx, (v - cam.cy) * d / cam.fy, d));
  if (voxel) {
    Block* block = lookup->lastBlock();
    addToRun(block, block->indexOf(*voxel), label, run, out);
  }
}

#ifdef PANMAP_HAVE_AVX2_PATH
__attribute__((target("avx2"))) inline __m256i notEqual(__m256i a, __m256i b) {
  return _mm256_xor_si256(_mm256_cmpeq_epi32(a, b), _mm256_set1_epi32(-1));
}

// The lane before each lane of x, where lane 0's is lane 7 of `last` (previous_lane: 7, 0, 1,
// ..., 6).
__attribute__((target("avx2"))) inline __m256i laneBefore(__m256i x, __m256i last,
                                                          __m256i previous_lane) {
  return _mm256_blend_epi32(_mm256_permutevar8x32_epi32(x, previous_lane),
                            _mm256_permutevar8x32_epi32(last, previous_lane), 1);
}

// Stride 1, eight pixels at a time: back-projection, the rigid transform and floor() in AVX2
// with the scalar path's operations in its order (Eigen multiplies the homogeneous 4x4 matrix
// row by row, ((r0 x + r1 y) + r2 z) + t, and nothing is contracted into FMA), so every pixel
// lands in the same voxel. Block lookups and runs stay scalar.
__attribute__((target("avx2"))) size_t findRowVotesAvx2(const Image<float>& depth_m,
                                                        const LabelImage& labels, int v,
                                                        const Eigen::Isometry3f& T_W_C,
                                                        const RowCamera& cam,
                                                        MutableVoxelLookup* lookup, VoteRun* out) {
  VoteRun* const first = out;
  VoteRun run{nullptr, -1, 0, 0};
  const int width = depth_m.width();
  const float* depth_row = &depth_m(0, v);
  const int32_t* label_row = &labels(0, v);
  const Eigen::Matrix4f& M = T_W_C.matrix();
  const __m256 cx = _mm256_set1_ps(cam.cx), fx = _mm256_set1_ps(cam.fx);
  const __m256 fy = _mm256_set1_ps(cam.fy);
  const __m256 v_minus_cy = _mm256_set1_ps(static_cast<float>(v) - cam.cy);
  const __m256 inv_voxel = _mm256_set1_ps(lookup->inverseVoxelSize());
  const __m256 lanes = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256 zero = _mm256_setzero_ps();
  __m256 m[3][4];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m[r][c] = _mm256_set1_ps(M(r, c));
  }
  alignas(32) int32_t block_index[3][8];
  alignas(32) int32_t voxel_offset[8];
  const __m256i seven = _mm256_set1_epi32(7);
  const __m256i previous_lane = _mm256_setr_epi32(7, 0, 1, 2, 3, 4, 5, 6);
  // Label, block index (x, y, z) and voxel offset of the lanes of the last group of eight: lane
  // 0 is compared with the last lane before it, so a stretch that crosses into this group
  // continues the open run without another lookup.
  __m256i last[5] = {};
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
    const __m256 x = _mm256_div_ps(_mm256_mul_ps(_mm256_sub_ps(uf, cx), d), fx);
    const __m256 y = _mm256_div_ps(_mm256_mul_ps(v_minus_cy, d), fy);
    // Voxel grid coordinates, split into block index (g >> 3) and place in the block.
    __m256i offset = _mm256_setzero_si256();
    // Lanes whose block index, voxel or label differ from the lane before.
    __m256i differs = notEqual(label, laneBefore(label, last[0], previous_lane));
    last[0] = label;
    for (int r = 0; r < 3; ++r) {
      const __m256 p = _mm256_add_ps(
          _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(m[r][0], x), _mm256_mul_ps(m[r][1], y)),
                        _mm256_mul_ps(m[r][2], d)),
          m[r][3]);
      const __m256i g = _mm256_cvttps_epi32(_mm256_floor_ps(_mm256_mul_ps(p, inv_voxel)));
      const __m256i b = _mm256_srai_epi32(g, 3);
      _mm256_store_si256(reinterpret_cast<__m256i*>(block_index[r]), b);
      differs = _mm256_or_si256(differs, notEqual(b, laneBefore(b, last[1 + r], previous_lane)));
      last[1 + r] = b;
      offset = _mm256_add_epi32(offset, _mm256_slli_epi32(_mm256_and_si256(g, seven), 3 * r));
    }
    differs =
        _mm256_or_si256(differs, notEqual(offset, laneBefore(offset, last[4], previous_lane)));
    last[4] = offset;
    _mm256_store_si256(reinterpret_cast<__m256i*>(voxel_offset), offset);
    static_assert(kBlockSide == 8, "block index and offset assume 8 voxels per block side");
    // One lookup per stretch of voting lanes with the same voxel and label (voxels wider than
    // a pixel make these long), not one per lane. A stretch starts where a voting lane differs
    // from the lane before or follows one that casts no vote, and ends before the next start
    // or non-voting lane; lane 0 continues the last group's lane 7 when both vote and agree.
    const int previous_votes = (valid << 1 | (continues ? 1 : 0)) & 0xFF;
    int starts = (_mm256_movemask_ps(_mm256_castsi256_ps(differs)) | ~previous_votes) & valid;
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
      last_block = lookup->findBlock(block_index[0][k], block_index[1][k], block_index[2][k]);
      if (last_block) {
        addToRun(last_block, voxel_offset[k], label_row[u + k], &run, &out,
                 static_cast<uint32_t>(stretchEnd(k) - k));
      }
    }
  }
  for (; u < width; ++u) {  // the last pixels of a row not a multiple of 8 wide
    votePixel(depth_m, labels, u, v, T_W_C, cam, lookup, &run, &out);
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
  for (int u = 0; u < depth_m.width(); u += stride) {
    votePixel(depth_m, labels, u, v, T_W_C, cam, lookup, &run, &out);
  }
  if (run.count > 0) *out++ = run;
  return static_cast<size_t>(out - first);
}

bool voteRowsUseAvx2() { return cpuHasAvx2(); }

size_t findRowVotes(const Image<float>& depth_m, const LabelImage& labels, int v, int stride,
                    const Eigen::Isometry3f& T_W_C, const RowCamera& cam,
                    MutableVoxelLookup* lookup, VoteRun* out) {
#ifdef PANMAP_HAVE_AVX2_PATH
  if (stride == 1 && voteRowsUseAvx2()) {
    return findRowVotesAvx2(depth_m, labels, v, T_W_C, cam, lookup, out);
  }
#endif
  return findRowVotesScalar(depth_m, labels, v, stride, T_W_C, cam, lookup, out);
}

}  // namespace internal
}  // namespace panmap
