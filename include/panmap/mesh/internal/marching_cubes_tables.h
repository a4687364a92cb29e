#pragma once

#include <cstdint>

namespace panmap {
namespace internal {

// The classic marching-cubes case tables (Lorensen & Cline 1987, in Paul Bourke's public-domain
// 256-case form). Cube corner i sits at kMcCornerOffset[i] (voxel steps); cube edge e joins
// corners kMcEdgeCorners[e]. A case index has bit i set when corner i is inside (sdf < 0).

/// Corner offsets of a cube, voxel steps along x, y, z.
constexpr int kMcCornerOffset[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                       {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};

/// The two corners of each of the 12 cube edges.
constexpr int kMcEdgeCorners[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                       {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

/// Triangles of each case as triples of cube edges, -1 terminated (at most 5 triangles).
extern const int8_t kMcTriangles[256][16];

}  // namespace internal
}  // namespace panmap
