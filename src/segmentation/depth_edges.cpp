// Edges of the geometric segmentation: concavity (min convexity) and depth discontinuity
// (paper III-A, after Furrer et al.'s released depth_segmentation).
#include <algorithm>
#include <cmath>

#include "panmap/segmentation/internal/depth_edges.h"
#include "panmap/core/vector_clones.h"

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

PANMAP_VECTOR_CLONES
void minInto(const float* values, int begin, int end, float* target) {
  for (int u = begin; u < end; ++u) target[u] = values[u] < target[u] ? values[u] : target[u];
}

}  // namespace

PANMAP_VECTOR_CLONES
void computeEdgeRows(const DepthGeometry& g, const DepthSegmentationConfig& config, int v0, int v1,
                     EdgeScratch* scratch, EdgeMaps* edges) {
  const int width = g.width;
  const int height = g.height;
  const int rc = config.min_convexity_window_px / 2;
  // One row for pair convexities, two (with room for the shift) absorbing the minima of rows
  // outside the band.
  scratch->pair_convexity.resize(width);
  scratch->outside_i.resize(width);
  scratch->outside_j.resize(width + 2 * rc);
  float* pair = scratch->pair_convexity.data();

  // Min convexity. A pair's convexity is symmetric, so only offsets of the lower half window
  // are computed and each result goes to both pixels; rows above the band contribute to it
  // through their pairs with the band.
  for (int v = v0; v < v1; ++v) std::fill_n(edges->min_convexity.row(v), width, 1.0f);
  for (int v = std::max(0, v0 - rc); v < v1; ++v) {
    for (int dy = 0; dy <= rc; ++dy) {
      const int vj = v + dy;
      if (vj >= height || vj < v0) continue;
      for (int dx = -rc; dx <= rc; ++dx) {
        if (dy == 0 && dx <= 0) continue;
        const int u_begin = std::max(0, -dx);
        const int u_end = std::min(width, width - dx);
        if (dy == 0) {
          // Both ends in one row: the minima overlap, so through the pair row.
          pairConvexityRow(g, v, dx, dy, u_begin, u_end, pair, nullptr, nullptr);
          minInto(pair, u_begin, u_end, edges->min_convexity.row(v));
          minInto(pair, u_begin, u_end, edges->min_convexity.row(v) + dx);
          continue;
        }
        float* min_i = v >= v0 ? edges->min_convexity.row(v) : scratch->outside_i.data();
        float* min_j =
            vj < v1 ? edges->min_convexity.row(vj) + dx : scratch->outside_j.data() + rc + dx;
        pairConvexityRow(g, v, dx, dy, u_begin, u_end, nullptr, min_i, min_j);
      }
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
