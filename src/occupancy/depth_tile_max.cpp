#include "panmap/occupancy/internal/depth_tile_max.h"

#include <algorithm>

namespace panmap {
namespace internal {

void DepthTileMax::build(const DepthImage& depth) {
  const int width = depth.width(), height = depth.height();
  tiles_x_ = (width + kTilePx - 1) / kTilePx;
  tiles_y_ = (height + kTilePx - 1) / kTilePx;
  max_.resize(static_cast<size_t>(tiles_x_) * tiles_y_);
  // Maxima down the columns of a band of rows first (a loop the compiler vectorises), then
  // across each tile's columns once per band.
  column_max_.resize(static_cast<size_t>(width));
  for (int ty = 0; ty < tiles_y_; ++ty) {
    std::fill(column_max_.begin(), column_max_.end(), uint16_t{0});
    uint16_t* __restrict columns = column_max_.data();
    for (int v = ty * kTilePx; v < std::min(height, (ty + 1) * kTilePx); ++v) {
      const uint16_t* __restrict row = depth.row(v);
      for (int u = 0; u < width; ++u) columns[u] = std::max(columns[u], row[u]);
    }
    uint16_t* tiles = &max_[static_cast<size_t>(ty) * tiles_x_];
    for (int tx = 0; tx < tiles_x_; ++tx) {
      const int end = std::min(width, (tx + 1) * kTilePx);
      tiles[tx] = *std::max_element(columns + tx * kTilePx, columns + end);
    }
  }
}

uint16_t DepthTileMax::maxOver(int u0, int v0, int u1, int v1) const {
  uint16_t m = 0;
  for (int ty = v0 / kTilePx; ty <= v1 / kTilePx; ++ty) {
    const uint16_t* tiles = &max_[static_cast<size_t>(ty) * tiles_x_];
    for (int tx = u0 / kTilePx; tx <= u1 / kTilePx; ++tx) m = std::max(m, tiles[tx]);
  }
  return m;
}

}  // namespace internal
}  // namespace panmap
