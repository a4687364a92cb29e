#pragma once

#include <cstdint>
#include <vector>

#include "panmap/core/image.h"
#include "panmap/segmentation/internal/depth_geometry.h"
#include "panmap/segmentation/panoptic_geometric.h"

namespace panmap {
namespace internal {

/// Edge maps of one frame.
struct EdgeMaps {
  Image<float> min_convexity;  ///< minimum pair convexity over the window, 1 = convex / flat
  Image<uint8_t> flags;        ///< DepthEdge bits, 0 = not an edge
  Image<uint8_t> segmentable;  ///< 255 where flags == 0 (the input of connected components)

  /// Sizes the maps (no reallocation when the size is unchanged).
  void resize(int width, int height);
};

/// Convexity of a pixel pair (i, j) after Furrer et al.: 1 where the surface between them is
/// flat or bends convexly, n_i . n_j where it bends concavely. The bend is judged on the
/// symmetric sum of both one-sided tests, (p_j - p_i) . n_i + (p_i - p_j) . n_j =
/// (p_j - p_i) . (n_i - n_j) > 0 (Stein et al.'s LCCP criterion) rather than on
/// (p_j - p_i) . n_i alone: box-filtered normals blend across a crease, and near a convex
/// crease the blended n_i makes its own face look concave to the one-sided test. The sum is
/// blend-invariant, and symmetric in i and j, so each pair is computed once.
/// (p_j - p_i) = (dx_m, dy_m, dz_m); n_i and n_j unit normals toward the camera.
inline float pairConvexity(float dx_m, float dy_m, float dz_m, float nix, float niy, float niz,
                           float njx, float njy, float njz) {
  const float bend_m = dx_m * (nix - njx) + dy_m * (niy - njy) + dz_m * (niz - njz);
  const float normals_cos = nix * njx + niy * njy + niz * njz;
  // bend_m > 0 ? normals_cos : 1, as arithmetic on a 0/1 factor so that row loops vectorise.
  const float concave = bend_m > 0.0f ? 1.0f : 0.0f;
  return 1.0f - concave * (1.0f - normals_cos);
}

/// Per-thread scratch of computeEdgeRows.
struct EdgeScratch {
  std::vector<float> pair_convexity;  ///< one row of pair convexities
  std::vector<float> outside_i;       ///< absorbs minima of pixels i outside the band
  std::vector<float> outside_j;       ///< absorbs minima of pixels j outside the band
  std::vector<float> chunk;           ///< AVX2 path: one chunk's pair convexities per offset
};

/// How computeEdgeRows computes the pairs of one row offset: `kFastest` takes the AVX2 path
/// where the CPU has it (all offsets of a row in one pass), `kScalar` one offset at a time;
/// both give the same bits.
enum class EdgePath { kFastest, kScalar };

/// Edge maps of rows [v0, v1): min convexity over the min_convexity_window_px window, then
/// the flags from it, from the discontinuities, invalid depth and missing normals. Reads the
/// geometry of rows within the window's radius of the band; writes only rows [v0, v1).
void computeEdgeRows(const DepthGeometry& geometry, const DepthSegmentationConfig& config, int v0,
                     int v1, EdgeScratch* scratch, EdgeMaps* edges,
                     EdgePath path = EdgePath::kFastest);

}  // namespace internal
}  // namespace panmap
