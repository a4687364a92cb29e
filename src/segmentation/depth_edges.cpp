// Edges of the geometric segmentation: concavity (min convexity) and depth discontinuity
// (paper III-A, after Furrer et al.'s released depth_segmentation).
#include <algorithm>
#include <cmath>

#include "panmap/core/cpu_features.h"
#include "panmap/core/vector_clones.h"
#include "panmap/segmentation/internal/depth_edges.h"

namespace panmap {
namespace internal {

void EdgeMaps::resize(int width, int height) {
  if (flags.width() == width && flags.height() == height) return;
  min_convexity = Image<float>(width, height, 1.0f);
  flags = Image<uint8_t>(width, height, 0);
  segmentable = Image<uint8_t>(width, height, 0);
}

namespace {

// Pair convexities of pixels i = (u, v) and j = (u + dx, v + dy) for u in [u_begin, u_end):
// into out[u] when min_i and min_j are null, else as minima into min_i[u] (row v) and
// min_j[u] (row v + dy, shifted by dx), which must not overlap.
PANMAP_VECTOR_CLONES
void pairConvexityRow(const DepthGeometry& g, int v, int dx, int dy, int u_begin, int u_end,
                      float* out, float* min_i, float* min_j) {
  const size_t i0 = g.index(0, v);
  const size_t j0 = g.index(0, v + dy) + dx;
  const float* __restrict xi = g.x_m.data() + i0;
  const float* __restrict yi = g.y_m.data() + i0;
  const float* __restrict zi = g.z_m.data() + i0;
  const float* __restrict nxi = g.nx.data() + i0;
  const float* __restrict nyi = g.ny.data() + i0;
  const float* __restrict nzi = g.nz.data() + i0;
  const float* __restrict hi = g.has_normal.data() + i0;
  const float* __restrict xj = g.x_m.data() + j0;
  const float* __restrict yj = g.y_m.data() + j0;
  const float* __restrict zj = g.z_m.data() + j0;
  const float* __restrict nxj = g.nx.data() + j0;
  const float* __restrict nyj = g.ny.data() + j0;
  const float* __restrict nzj = g.nz.data() + j0;
  const float* __restrict hj = g.has_normal.data() + j0;
  auto convexity = [&](int u) {
    const float c = pairConvexity(xj[u] - xi[u], yj[u] - yi[u], zj[u] - zi[u], nxi[u], nyi[u],
                                  nzi[u], nxj[u], nyj[u], nzj[u]);
    // A pixel without a normal has no say (it is an edge of its own): has_normal is 0 or 1.
    return 1.0f - hi[u] * hj[u] * (1.0f - c);
  };
  if (min_i == nullptr) {
    float* __restrict o = out;
#pragma GCC ivdep
    for (int u = u_begin; u < u_end; ++u) o[u] = convexity(u);
    return;
  }
  float* __restrict mi = min_i;
  float* __restrict mj = min_j;
#pragma GCC ivdep
  for (int u = u_begin; u < u_end; ++u) {
    const float c = convexity(u);
    mi[u] = c < mi[u] ? c : mi[u];
    mj[u] = c < mj[u] ? c : mj[u];
  }
}

#ifdef PANMAP_HAVE_AVX2_PATH
// Pixels per chunk of the AVX2 path: its pair values, one row per offset, stay in L1.
constexpr int kChunkPx = 128;

// Pairs of pixels i = (u, v) and j = (u + dx, v + dy) for every dx in [dx_first, dx_last], u in
// [u_begin, u_end) (a multiple of 8 pixels, every u + dx inside the row; min_i and min_j are
// rows v and v + dy, the same row when dy = 0, where dx_first > 0): pairConvexityRow's
// arithmetic in the same order (nothing contracted into FMA), so every pair gets its bits.
// Pixel i's seven planes are loaded once for all its pairs, whose minimum is kept in
// a register; the pairs' values then reach the j pixels' minima (min_j + dx) one offset at a
// time through `chunk`, a pass per offset: updating them right away would have each load of
// min_j read the store of the offset before, one pixel over, which the CPU cannot forward.
__attribute__((target("avx2"))) void pairConvexityRowsAvx2(const DepthGeometry& g, int v, int dy,
                                                           int dx_first, int dx_last, int u_begin,
                                                           int u_end, float* min_i, float* min_j,
                                                           float* chunk) {
  const size_t i0 = g.index(0, v);
  const size_t j0 = g.index(0, v + dy);
  const float* const planes[7] = {g.x_m.data(), g.y_m.data(), g.z_m.data(),       g.nx.data(),
                                  g.ny.data(),  g.nz.data(),  g.has_normal.data()};
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m256 zero = _mm256_setzero_ps();
  for (int c0 = u_begin; c0 < u_end; c0 += kChunkPx) {
    const int c1 = std::min(u_end, c0 + kChunkPx);
    for (int u = c0; u < c1; u += 8) {
      __m256 pi[7];
      for (int k = 0; k < 7; ++k) pi[k] = _mm256_loadu_ps(planes[k] + i0 + u);
      __m256 lowest = _mm256_loadu_ps(min_i + u);
      for (int dx = dx_first; dx <= dx_last; ++dx) {
        __m256 pj[7];
        for (int k = 0; k < 7; ++k) pj[k] = _mm256_loadu_ps(planes[k] + j0 + u + dx);
        const __m256 bend = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(pj[0], pi[0]), _mm256_sub_ps(pi[3], pj[3])),
                          _mm256_mul_ps(_mm256_sub_ps(pj[1], pi[1]), _mm256_sub_ps(pi[4], pj[4]))),
            _mm256_mul_ps(_mm256_sub_ps(pj[2], pi[2]), _mm256_sub_ps(pi[5], pj[5])));
        const __m256 normals_cos =
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(pi[3], pj[3]), _mm256_mul_ps(pi[4], pj[4])),
                          _mm256_mul_ps(pi[5], pj[5]));
        const __m256 concave = _mm256_and_ps(_mm256_cmp_ps(bend, zero, _CMP_GT_OQ), one);
        const __m256 c =
            _mm256_sub_ps(one, _mm256_mul_ps(concave, _mm256_sub_ps(one, normals_cos)));
        const __m256 value =
            _mm256_sub_ps(one, _mm256_mul_ps(_mm256_mul_ps(pi[6], pj[6]), _mm256_sub_ps(one, c)));
        lowest = _mm256_min_ps(value, lowest);  // value < lowest ? value : lowest
        _mm256_storeu_ps(chunk + (dx - dx_first) * kChunkPx + (u - c0), value);
      }
      _mm256_storeu_ps(min_i + u, lowest);
    }
    for (int dx = dx_first; dx <= dx_last; ++dx) {
      const float* values = chunk + (dx - dx_first) * kChunkPx - c0;  // indexed by u
      float* target = min_j + dx;
      for (int u = c0; u < c1; u += 8) {
        const __m256 now = _mm256_loadu_ps(target + u);
        _mm256_storeu_ps(target + u, _mm256_min_ps(_mm256_loadu_ps(values + u), now));
      }
    }
  }
}
#endif

PANMAP_VECTOR_CLONES
void minInto(const float* values, int begin, int end, float* target) {
  for (int u = begin; u < end; ++u) target[u] = values[u] < target[u] ? values[u] : target[u];
}

}  // namespace

PANMAP_VECTOR_CLONES
void computeEdgeRows(const DepthGeometry& g, const DepthSegmentationConfig& config, int v0, int v1,
                     EdgeScratch* scratch, EdgeMaps* edges, EdgePath path) {
  const int width = g.width;
  const int height = g.height;
  const int rc = config.min_convexity_window_px / 2;
  // One row for pair convexities, two (with room for the shift) absorbing the minima of rows
  // outside the band.
  scratch->pair_convexity.resize(width);
  scratch->outside_i.resize(width);
  scratch->outside_j.resize(width + 2 * rc);
  float* pair = scratch->pair_convexity.data();
  // The AVX2 path takes the pixels whose every pair lies inside the row, in whole vectors.
  int fused_begin = 0, fused_end = 0;
  static_cast<void>(path);  // one path only without AVX2 support in the compiler
#ifdef PANMAP_HAVE_AVX2_PATH
  if (path == EdgePath::kFastest && cpuHasAvx2() && width - 2 * rc >= 8) {
    fused_begin = rc;
    fused_end = rc + (width - 2 * rc) / 8 * 8;
    scratch->chunk.resize(static_cast<size_t>(2 * rc + 1) * kChunkPx);
  }
#endif

  // Min convexity. A pair's convexity is symmetric, so only offsets of the lower half window
  // are computed and each result goes to both pixels; rows above the band contribute to it
  // through their pairs with the band.
  for (int v = v0; v < v1; ++v) std::fill_n(edges->min_convexity.row(v), width, 1.0f);
  for (int v = std::max(0, v0 - rc); v < v1; ++v) {
    for (int dy = 0; dy <= rc; ++dy) {
      const int vj = v + dy;
      if (vj >= height || vj < v0) continue;
      float* min_i = v >= v0 ? edges->min_convexity.row(v) : scratch->outside_i.data();
      float* min_j = vj < v1 ? edges->min_convexity.row(vj) : scratch->outside_j.data() + rc;
      const int dx_first = dy == 0 ? 1 : -rc;
      for (int dx = dx_first; dx <= rc; ++dx) {
        // The pixels the AVX2 path leaves out: all of them, or those before and after it.
        const int u_begin = std::max(0, -dx);
        const int u_end = std::min(width, width - dx);
        const bool split = fused_end > fused_begin;
        for (const auto& [b, e] : {std::make_pair(u_begin, split ? fused_begin : u_end),
                                   std::make_pair(split ? fused_end : u_end, u_end)}) {
          if (b >= e) continue;
          if (dy == 0) {
            // Both ends in one row: the minima overlap, so through the pair row.
            pairConvexityRow(g, v, dx, dy, b, e, pair, nullptr, nullptr);
            minInto(pair, b, e, min_i);
            minInto(pair, b, e, min_j + dx);
          } else {
            pairConvexityRow(g, v, dx, dy, b, e, nullptr, min_i, min_j + dx);
          }
        }
      }
#ifdef PANMAP_HAVE_AVX2_PATH
      if (fused_end > fused_begin) {
        pairConvexityRowsAvx2(g, v, dy, dx_first, rc, fused_begin, fused_end, min_i, min_j,
                              scratch->chunk.data());
      }
#endif
    }
  }

  const float threshold = config.min_convexity_threshold;
  for (int v = v0; v < v1; ++v) {
    const size_t i0 = g.index(0, v);
    const float* __restrict z = g.z_m.data() + i0;
    const float* __restrict has = g.has_normal.data() + i0;
    const float* __restrict jump = g.discontinuity.data() + i0;
    const float* __restrict convexity = edges->min_convexity.row(v);
    uint8_t* __restrict flags = edges->flags.row(v);
    uint8_t* __restrict segmentable = edges->segmentable.row(v);
#pragma GCC ivdep
    for (int u = 0; u < width; ++u) {
      const bool valid = z[u] > 0.0f;
      const int bits = (valid ? 0 : kEdgeInvalidDepth) |
                       ((valid & (has[u] == 0.0f)) ? kEdgeNoNormal : 0) |
                       (jump[u] != 0.0f ? kEdgeDiscontinuity : 0) |
                       (convexity[u] < threshold ? kEdgeConcave : 0);
      flags[u] = static_cast<uint8_t>(bits);
      segmentable[u] = bits == 0 ? 255 : 0;
    }
  }
}

}  // namespace internal
}  // namespace panmap
