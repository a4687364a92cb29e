#pragma once

#include <cstdint>
#include <vector>

#include "panmap/core/image.h"

namespace panmap {
namespace internal {

/// The largest raw depth of each 8x8 pixel tile of a depth image, for a quick upper bound of
/// the depth over a pixel rectangle: the free-space pass skips blocks of cells that lie behind
/// the surface everywhere they project.
class DepthTileMax {
 public:
  /// Pixels per tile side.
  static constexpr int kTilePx = 8;

  /// Recomputes the tiles for `depth` (any size; edge tiles are partial).
  void build(const DepthImage& depth);

  /// An upper bound of depth(u, v) over u in [u0, u1], v in [v0, v1] (inclusive, inside the
  /// image): the maximum over the tiles the rectangle touches.
  uint16_t maxOver(int u0, int v0, int u1, int v1) const;

 private:
  int tiles_x_ = 0, tiles_y_ = 0;
  std::vector<uint16_t> max_;         // row-major tiles
  std::vector<uint16_t> column_max_;  // scratch of build()
};

}  // namespace internal
}  // namespace panmap
