#include "panmap/map/internal/block_integration.h"

#include <algorithm>

#include "panmap/core/cpu_features.h"

namespace panmap {
namespace internal {

namespace {

// Rounds half away from zero like std::lround, for x > -0.5 (callers reject the rest), without
// the library call: truncation is floor for x >= 0 and the fraction x - floor(x) is exact.
inline int roundPositive(float x) {
  const int i = static_cast<int>(x);
  return x - static_cast<float>(i) >= 0.5f ? i + 1 : i;
}

// floor(x) for x > -1.
inline int floorAboveMinusOne(float x) { return x < 0.0f ? -1 : static_cast<int>(x); }

// Depth seen through (uf, vf): bilinear between the four surrounding pixels on a smooth
// surface (nearest-pixel depth on slanted surfaces is off by up to half a pixel's depth
// change, centimetres at grazing angles), the nearest pixel (u, v) across depth edges or
// holes. uf, vf > -0.5.
inline float sampleDepth(const Image<float>& depth, float uf, float vf, int u, int v) {
  const int u0 = floorAboveMinusOne(uf), v0 = floorAboveMinusOne(vf);
  const int w = depth.width();
  if (u0 < 0 || v0 < 0 || u0 + 1 >= w || v0 + 1 >= depth.height()) return depth(u, v);
  const float* row0 = &depth(u0, v0);
  const float* row1 = row0 + w;
  const float d00 = row0[0], d10 = row0[1], d01 = row1[0], d11 = row1[1];
  const float lo = std::min(std::min(d00, d10), std::min(d01, d11));
  const float hi = std::max(std::max(d00, d10), std::max(d01, d11));
  if (lo <= 0.0f || hi - lo > 0.05f * lo) return depth(u, v);
  const float a = uf - u0, b = vf - v0;
  return (1 - b) * ((1 - a) * d00 + a * d10) + b * ((1 - a) * d01 + a * d11);
}

// The lower neighbours (Block::lower_changed bits) whose cubes read a voxel of row (y, z) whose
// bit is set in `fused` (bit x for voxel x).
inline uint8_t lowerNeighboursReading(uint32_t fused, int y, int z) {
  if (fused == 0) return 0;
  uint8_t slots = 0xFE;
  if (!(fused & 1u)) slots &= static_cast<uint8_t>(~0xAAu);  // 1, 3, 5, 7 read x = 0 only
  if (y != 0) slots &= static_cast<uint8_t>(~0xCCu);         // 2, 3, 6, 7 read y = 0 only
  if (z != 0) slots &= static_cast<uint8_t>(~0xF0u);         // 4, 5, 6, 7 read z = 0 only
  return slots;
}

// Fuses measured depth d (> 0) seen through pixel (u, v) into a voxel at depth z whose distance
// and weight are given as floats (updated in place) and whose colour is `color`. Returns
// whether the voxel changed. Both paths call this, so they agree bit for bit; they differ only
// in how they convert the voxel's 2-byte floats, which is exact one way and rounds to nearest
// even the other, in both.
inline bool fuseValues(const BlockUpdateParams& p, float z, float d, int u, int v, float* sdf_m,
                       float* weight_sum, Rgb8* color) {
  const float trunc = p.truncation_m;
  // Projective distance along the optical axis.
  const float sdf = d - z;
  if (sdf < -trunc) return false;  // hidden behind the surface
  // Far in front of the surface: free space. Only carving records it; otherwise a voxel
  // inside an object near its silhouette, whose projection misses the object and lands on the
  // background, would be pulled outward.
  if (sdf > trunc && !p.space_carving) return false;
  float weight = 1.0f;
  if (p.weight_dropoff && sdf < -p.voxel_m) weight = (trunc + sdf) / (trunc - p.voxel_m);
  if (weight <= 0.0f) return false;
  const float s = std::min(sdf, trunc);
  const float total = *weight_sum + weight;
  *sdf_m = (*sdf_m * *weight_sum + s * weight) / total;
  if (p.color && sdf < trunc) {
    const Rgb8 c = (*p.color)(u, v);
    const float a = weight / total;
    color->r = static_cast<uint8_t>(color->r + a * (c.r - color->r) + 0.5f);
    color->g = static_cast<uint8_t>(color->g + a * (c.g - color->g) + 0.5f);
    color->b = static_cast<uint8_t>(color->b + a * (c.b - color->b) + 0.5f);
  }
  *weight_sum = std::min(total, p.max_weight);
  return true;
}

// fuseValues on a voxel, converting its 2-byte floats in software (Float16).
inline bool fuseVoxel(const BlockUpdateParams& p, float z, float d, int u, int v, Voxel* vox) {
  float sdf_m = vox->sdf_m, weight = vox->weight;
  if (!fuseValues(p, z, d, u, v, &sdf_m, &weight, &vox->color)) return false;
  vox->sdf_m = sdf_m;
  vox->weight = weight;
  return true;
}

// Camera-frame centres of one x-row of voxels, accumulated exactly as the scalar loop does.
inline void rowCentres(const Eigen::Vector3f& origin_C, const Eigen::Vector3f& dx,
                       const Eigen::Vector3f& dy, const Eigen::Vector3f& dz, int y, int z,
                       float* xs, float* ys, float* zs) {
  Eigen::Vector3f p_C = origin_C + dy * static_cast<float>(y) + dz * static_cast<float>(z);
  for (int x = 0; x < kBlockSide; ++x, p_C += dx) {
    xs[x] = p_C.x();
    ys[x] = p_C.y();
    zs[x] = p_C.z();
  }
}

#ifdef PANMAP_HAVE_AVX2_PATH
static_assert(kBlockSide == 8, "the AVX2 path handles one 8-voxel row per vector");

// Asks for the cache lines of an x-row of voxels.
inline void prefetchRow(const Voxel* row) {
  const char* bytes = reinterpret_cast<const char*>(row);
  constexpr size_t kBytes = kBlockSide * sizeof(Voxel);
  static_assert(kBytes % 64 == 0, "rows start on a cache line (Block::voxels)");
  for (size_t k = 0; k < kBytes; k += 64) _mm_prefetch(bytes + k, _MM_HINT_T0);
}

// One x-row per 8-wide vector: projection, bounds, rounding and the bilinear depth sample are
// the scalar path's IEEE operations in the same order (no FMA: the target is avx2 and f16c),
// so results are identical; only voxels left in the band go through the scalar update, whose
// 2-byte floats F16C converts (exactly to float, to nearest even back, as Float16 does).
__attribute__((target("avx2,f16c"))) size_t updateBlockAvx2(const BlockUpdateParams& p,
                                                            const Eigen::Vector3f& origin_C,
                                                            Block* block) {
  const Eigen::Vector3f dx = p.R_C_W.col(0) * p.voxel_m, dy = p.R_C_W.col(1) * p.voxel_m,
                        dz = p.R_C_W.col(2) * p.voxel_m;
  const Image<float>& depth = *p.depth_m;
  const int w = depth.width(), h = depth.height();
  const float* base = depth.data();
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const __m256 half = _mm256_set1_ps(0.5f), minus_half = _mm256_set1_ps(-0.5f);
  const __m256 fx = _mm256_set1_ps(p.fx), fy = _mm256_set1_ps(p.fy);
  const __m256 cx = _mm256_set1_ps(p.cx), cy = _mm256_set1_ps(p.cy);
  const __m256 min_depth = _mm256_set1_ps(p.min_depth_m);
  const __m256 u_max = _mm256_set1_ps(static_cast<float>(w) - 0.5f);
  const __m256 v_max = _mm256_set1_ps(static_cast<float>(h) - 0.5f);
  const __m256 edge_ratio = _mm256_set1_ps(0.05f);
  const __m256 neg_trunc = _mm256_set1_ps(-p.truncation_m);
  const __m256 trunc = _mm256_set1_ps(p.truncation_m);
  const __m256i minus_one = _mm256_set1_epi32(-1), width = _mm256_set1_epi32(w);
  const __m256i last_u = _mm256_set1_epi32(w - 1), last_v = _mm256_set1_epi32(h - 1);
  alignas(32) float xs[8], ys[8], zs[8], ds[8];
  alignas(32) int us[8], vs[8], pixel[8];
  const char* color_bytes = p.color ? reinterpret_cast<const char*>(p.color->data()) : nullptr;
  size_t updated = 0;
  for (int z = 0; z < kBlockSide; ++z) {
    for (int y = 0; y < kBlockSide; ++y) {
      rowCentres(origin_C, dx, dy, dz, y, z, xs, ys, zs);
      const __m256 X = _mm256_load_ps(xs), Y = _mm256_load_ps(ys), Z = _mm256_load_ps(zs);
      __m256 valid = _mm256_cmp_ps(Z, min_depth, _CMP_GE_OQ);
      if (_mm256_movemask_ps(valid) == 0) continue;
      const __m256 inv_z = _mm256_div_ps(one, Z);
      const __m256 uf = _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(fx, X), inv_z), cx);
      const __m256 vf = _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(fy, Y), inv_z), cy);
      valid = _mm256_and_ps(valid, _mm256_cmp_ps(uf, minus_half, _CMP_GT_OQ));
      valid = _mm256_and_ps(valid, _mm256_cmp_ps(vf, minus_half, _CMP_GT_OQ));
      valid = _mm256_and_ps(valid, _mm256_cmp_ps(uf, u_max, _CMP_LT_OQ));
      valid = _mm256_and_ps(valid, _mm256_cmp_ps(vf, v_max, _CMP_LT_OQ));
      if (_mm256_movemask_ps(valid) == 0) continue;
      // A block's voxels are mostly not in cache, nor are the colours they read: fetching the
      // row and its pixels now overlaps those misses with the depth gathers below (the voxel
      // loads were a third of this function's samples in perf).
      prefetchRow(&block->at(0, y, z));
      // Lanes outside the image compute on 0 (never read back).
      const __m256 us_f = _mm256_blendv_ps(zero, uf, valid);
      const __m256 vs_f = _mm256_blendv_ps(zero, vf, valid);
      const __m256i ut = _mm256_cvttps_epi32(us_f), vt = _mm256_cvttps_epi32(vs_f);
      // roundPositive: truncation plus one where the exact fraction is >= 0.5.
      const __m256 u_up =
          _mm256_cmp_ps(_mm256_sub_ps(us_f, _mm256_cvtepi32_ps(ut)), half, _CMP_GE_OQ);
      const __m256 v_up =
          _mm256_cmp_ps(_mm256_sub_ps(vs_f, _mm256_cvtepi32_ps(vt)), half, _CMP_GE_OQ);
      const __m256i u = _mm256_sub_epi32(ut, _mm256_castps_si256(u_up));
      const __m256i v = _mm256_sub_epi32(vt, _mm256_castps_si256(v_up));
      _mm256_store_si256(reinterpret_cast<__m256i*>(pixel),
                         _mm256_add_epi32(_mm256_mullo_epi32(v, width), u));
      if (p.color) {
        for (int lane = _mm256_movemask_ps(valid); lane != 0; lane &= lane - 1) {
          _mm_prefetch(color_bytes + 3 * pixel[__builtin_ctz(static_cast<unsigned>(lane))],
                       _MM_HINT_T0);
        }
      }
      // floorAboveMinusOne: truncation, minus one for (-0.5, 0).
      const __m256i u0 =
          _mm256_add_epi32(ut, _mm256_castps_si256(_mm256_cmp_ps(us_f, zero, _CMP_LT_OQ)));
      const __m256i v0 =
          _mm256_add_epi32(vt, _mm256_castps_si256(_mm256_cmp_ps(vs_f, zero, _CMP_LT_OQ)));
      __m256i inside =
          _mm256_and_si256(_mm256_cmpgt_epi32(u0, minus_one), _mm256_cmpgt_epi32(v0, minus_one));
      inside = _mm256_and_si256(inside, _mm256_cmpgt_epi32(last_u, u0));
      inside = _mm256_and_si256(inside, _mm256_cmpgt_epi32(last_v, v0));
      const __m256 four = _mm256_and_ps(_mm256_castsi256_ps(inside), valid);
      // The nearest pixel: gathered only at the image border, elsewhere one of the four below
      // (u is u0 or u0 + 1, v is v0 or v0 + 1).
      const __m256 border = _mm256_andnot_ps(four, valid);
      __m256 d = zero;
      if (_mm256_movemask_ps(border) != 0) {
        d = _mm256_mask_i32gather_ps(
            zero, base, _mm256_load_si256(reinterpret_cast<__m256i*>(pixel)), border, 4);
      }
      if (_mm256_movemask_ps(four) != 0) {
        const __m256i i00 = _mm256_add_epi32(_mm256_mullo_epi32(v0, width), u0);
        const __m256 d00 = _mm256_mask_i32gather_ps(zero, base, i00, four, 4);
        const __m256 d10 = _mm256_mask_i32gather_ps(zero, base + 1, i00, four, 4);
        const __m256 d01 = _mm256_mask_i32gather_ps(zero, base + w, i00, four, 4);
        const __m256 d11 = _mm256_mask_i32gather_ps(zero, base + w + 1, i00, four, 4);
        const __m256 d_near = _mm256_blendv_ps(_mm256_blendv_ps(d00, d10, u_up),
                                               _mm256_blendv_ps(d01, d11, u_up), v_up);
        d = _mm256_blendv_ps(d, d_near, four);
        const __m256 lo = _mm256_min_ps(_mm256_min_ps(d00, d10), _mm256_min_ps(d01, d11));
        const __m256 hi = _mm256_max_ps(_mm256_max_ps(d00, d10), _mm256_max_ps(d01, d11));
        __m256 smooth = _mm256_and_ps(four, _mm256_cmp_ps(lo, zero, _CMP_GT_OQ));
        smooth = _mm256_and_ps(smooth, _mm256_cmp_ps(_mm256_sub_ps(hi, lo),
                                                     _mm256_mul_ps(edge_ratio, lo), _CMP_LE_OQ));
        const __m256 a = _mm256_sub_ps(us_f, _mm256_cvtepi32_ps(u0));
        const __m256 b = _mm256_sub_ps(vs_f, _mm256_cvtepi32_ps(v0));
        const __m256 one_a = _mm256_sub_ps(one, a), one_b = _mm256_sub_ps(one, b);
        const __m256 top = _mm256_add_ps(_mm256_mul_ps(one_a, d00), _mm256_mul_ps(a, d10));
        const __m256 bottom = _mm256_add_ps(_mm256_mul_ps(one_a, d01), _mm256_mul_ps(a, d11));
        const __m256 bilinear = _mm256_add_ps(_mm256_mul_ps(one_b, top), _mm256_mul_ps(b, bottom));
        d = _mm256_blendv_ps(d, bilinear, smooth);
      }
      // The band test again in vector form, so most voxels never reach the scalar update.
      const __m256 sdf = _mm256_sub_ps(d, Z);
      __m256 keep = _mm256_and_ps(valid, _mm256_cmp_ps(d, zero, _CMP_GT_OQ));
      keep = _mm256_and_ps(keep, _mm256_cmp_ps(sdf, neg_trunc, _CMP_GE_OQ));
      if (!p.space_carving) keep = _mm256_and_ps(keep, _mm256_cmp_ps(sdf, trunc, _CMP_LE_OQ));
      int lanes = _mm256_movemask_ps(keep);
      if (lanes == 0) continue;
      _mm256_store_ps(ds, d);
      _mm256_store_si256(reinterpret_cast<__m256i*>(us), u);
      _mm256_store_si256(reinterpret_cast<__m256i*>(vs), v);
      Voxel* row = &block->at(0, y, z);
      uint32_t fused = 0;
      for (; lanes != 0; lanes &= lanes - 1) {
        const int x = __builtin_ctz(static_cast<unsigned>(lanes));
        // fuseVoxel with the 2-byte floats converted by F16C instructions.
        Voxel& vox = row[x];
        float sdf_m = _cvtsh_ss(vox.sdf_m.bits()), weight = _cvtsh_ss(vox.weight.bits());
        if (!fuseValues(p, zs[x], ds[x], us[x], vs[x], &sdf_m, &weight, &vox.color)) continue;
        vox.sdf_m = Float16::fromBits(_cvtss_sh(sdf_m, _MM_FROUND_TO_NEAREST_INT));
        vox.weight = Float16::fromBits(_cvtss_sh(weight, _MM_FROUND_TO_NEAREST_INT));
        fused |= 1u << x;
      }
      updated += __builtin_popcount(fused);
      block->lower_changed |= lowerNeighboursReading(fused, y, z);
    }
  }
  return updated;
}
#endif

}  // namespace

size_t updateBlockScalar(const BlockUpdateParams& p, const Eigen::Vector3f& origin_C,
                         Block* block) {
  const Eigen::Vector3f dx = p.R_C_W.col(0) * p.voxel_m, dy = p.R_C_W.col(1) * p.voxel_m,
                        dz = p.R_C_W.col(2) * p.voxel_m;
  const Image<float>& depth = *p.depth_m;
  const float u_max = static_cast<float>(depth.width()) - 0.5f;
  const float v_max = static_cast<float>(depth.height()) - 0.5f;
  float xs[kBlockSide], ys[kBlockSide], zs[kBlockSide];
  size_t updated = 0;
  for (int z = 0; z < kBlockSide; ++z) {
    for (int y = 0; y < kBlockSide; ++y) {
      rowCentres(origin_C, dx, dy, dz, y, z, xs, ys, zs);
      Voxel* row = &block->at(0, y, z);
      uint32_t fused = 0;
      for (int x = 0; x < kBlockSide; ++x) {
        if (zs[x] < p.min_depth_m) continue;
        const float inv_z = 1.0f / zs[x];
        const float uf = p.fx * xs[x] * inv_z + p.cx, vf = p.fy * ys[x] * inv_z + p.cy;
        // The pixel (lround(uf), lround(vf)) must be inside the image.
        if (!(uf > -0.5f && vf > -0.5f && uf < u_max && vf < v_max)) continue;
        const int u = roundPositive(uf), v = roundPositive(vf);
        const float d = sampleDepth(depth, uf, vf, u, v);
        if (d <= 0.0f) continue;
        fused |= static_cast<uint32_t>(fuseVoxel(p, zs[x], d, u, v, &row[x])) << x;
      }
      updated += __builtin_popcount(fused);
      block->lower_changed |= lowerNeighboursReading(fused, y, z);
    }
  }
  return updated;
}

bool blockUpdateUsesAvx2() { return cpuHasAvx2F16c(); }

size_t updateBlock(const BlockUpdateParams& p, const Eigen::Vector3f& origin_C, Block* block) {
#ifdef PANMAP_HAVE_AVX2_PATH
  if (blockUpdateUsesAvx2()) return updateBlockAvx2(p, origin_C, block);
#endif
  return updateBlockScalar(p, origin_C, block);
}

}  // namespace internal
}  // namespace panmap
