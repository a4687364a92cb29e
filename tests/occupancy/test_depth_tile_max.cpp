// DepthTileMax against brute force on a random image whose size is not a multiple of a tile.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "panmap/occupancy/internal/depth_tile_max.h"

namespace panmap {
namespace internal {
namespace {

uint16_t bruteMax(const DepthImage& depth, int u0, int v0, int u1, int v1) {
  uint16_t m = 0;
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) m = std::max(m, depth(u, v));
  }
  return m;
}

TEST(DepthTileMax, BoundsEveryRectangleAndIsExactOnWholeTiles) {
  std::mt19937 rng(3);
  DepthImage depth(37, 21);  // partial tiles on the right and at the bottom
  for (size_t i = 0; i < depth.size(); ++i) depth.data()[i] = static_cast<uint16_t>(rng() % 60000);
  DepthTileMax tiles;
  tiles.build(depth);
  constexpr int kTile = DepthTileMax::kTilePx;
  for (int trial = 0; trial < 2000; ++trial) {
    int u0 = static_cast<int>(rng() % 37), u1 = static_cast<int>(rng() % 37);
    int v0 = static_cast<int>(rng() % 21), v1 = static_cast<int>(rng() % 21);
    if (u0 > u1) std::swap(u0, u1);
    if (v0 > v1) std::swap(v0, v1);
    // The bound is the exact maximum over the tiles the rectangle touches.
    const int tu0 = u0 / kTile * kTile, tv0 = v0 / kTile * kTile;
    const int tu1 = std::min(36, (u1 / kTile + 1) * kTile - 1);
    const int tv1 = std::min(20, (v1 / kTile + 1) * kTile - 1);
    const uint16_t bound = tiles.maxOver(u0, v0, u1, v1);
    ASSERT_GE(bound, bruteMax(depth, u0, v0, u1, v1));
    ASSERT_EQ(bound, bruteMax(depth, tu0, tv0, tu1, tv1));
  }
  // A rebuild follows the new image.
  depth.data()[depth.size() - 1] = 65535;
  tiles.build(depth);
  EXPECT_EQ(tiles.maxOver(36, 20, 36, 20), 65535);
}

}  // namespace
}  // namespace internal
}  // namespace panmap
