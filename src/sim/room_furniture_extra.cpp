// Furniture only ScanNet-like rooms get: box rooms never call these builders, so adding or
// changing them leaves every box room as it was.
#include <algorithm>

#include "panmap/sim/internal/room_furniture.h"

namespace panmap {
namespace internal {
namespace room {

Module buildDresser(RoomRng* rng, const BuildContext& ctx) {
  const float w = rng->uniform(0.8f, 1.4f);
  const float d = rng->uniform(0.42f, 0.5f);
  if (d + 0.02f > ctx.max_depth_m) return Module();
  const float h = rng->uniform(0.75f, 1.0f);
  const int drawers = rng->uniformInt(3, 4);
  Item dresser = makeItem(kDresser, "dresser", tint(rng, 150, 110, 75, 40));
  dresser.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, w, d - 0.02f, h));
  // Drawer fronts 1 cm apart, like the refrigerator's doors: one instance, many depth edges.
  const float z0 = 0.06f, pitch = (h - 0.03f - z0) / static_cast<float>(drawers);
  for (int k = 0; k < drawers; ++k) {
    const float lo = z0 + static_cast<float>(k) * pitch;
    const float hi = lo + pitch - 0.01f;
    dresser.parts.push_back(cuboid(0.02f, d - 0.02f, lo, w - 0.02f, d, hi));
    const float mid = 0.5f * (lo + hi);
    dresser.parts.push_back(
        cuboid(0.5f * w - 0.06f, d, mid - 0.01f, 0.5f * w + 0.06f, d + 0.02f, mid + 0.01f));
  }
  Module m;
  m.items.push_back(dresser);
  if (rng->chance(0.6)) {
    // A television on a foot: the screen overhangs the dresser top, its back near the wall.
    const float tw = std::min(rng->uniform(0.7f, 1.1f), w - 0.04f);
    const float th = 0.58f * tw;
    if (h + 0.13f + th < ctx.ceiling_m - 0.2f) {
      const float cx = 0.5f * w;
      Item tv = makeItem(kTelevision, "television", tint(rng, 30, 30, 34, 6));
      tv.parts.push_back(cuboid(cx - 0.14f, 0.08f, h, cx + 0.14f, 0.3f, h + 0.03f));
      tv.parts.push_back(cuboid(cx - 0.04f, 0.14f, h + 0.03f, cx + 0.04f, 0.18f, h + 0.13f));
      tv.parts.push_back(
          cuboid(cx - 0.5f * tw, 0.12f, h + 0.13f, cx + 0.5f * tw, 0.17f, h + 0.13f + th));
      m.items.push_back(tv);
    }
  }
  m.end_margin_m = 0.02f;
  return m;
}

Module buildWallShelf(RoomRng* rng, const BuildContext& ctx) {
  const float w = rng->uniform(0.6f, 1.2f);
  const float d = rng->uniform(0.2f, 0.26f);
  if (d > ctx.max_depth_m) return Module();
  const float z = std::min(rng->uniform(1.0f, 1.45f), ctx.ceiling_m - 0.6f);
  Item shelf = makeItem(kShelves, "shelves", tint(rng, 170, 140, 100, 45));
  shelf.parts.push_back(cuboid(0.0f, 0.0f, z - 0.025f, w, d, z));
  for (float x : {0.1f, w - 0.12f}) {
    shelf.parts.push_back(cuboid(x, 0.0f, z - 0.2f, x + 0.02f, d - 0.04f, z - 0.025f));
  }
  Module m;
  m.items.push_back(shelf);
  m.end_margin_m = 0.05f;
  return m;
}

Module buildWallBoard(RoomRng* rng, const BuildContext& ctx) {
  Module m;
  if (rng->chance(0.5)) {
    const float w = rng->uniform(0.9f, 1.8f);
    const float z0 = rng->uniform(0.85f, 1.0f);
    const float z1 = std::min(z0 + rng->uniform(0.6f, 1.1f), ctx.ceiling_m - 0.15f);
    Item board = makeItem(kWhiteboard, "whiteboard", tint(rng, 240, 242, 240, 6));
    board.parts.push_back(cuboid(0.0f, 0.0f, z0, w, 0.02f, z1));
    board.parts.push_back(cuboid(0.0f, 0.0f, z0 - 0.03f, w, 0.06f, z0));
    m.items.push_back(board);
  } else {
    const float w = rng->uniform(0.4f, 0.7f);
    const float z0 = rng->uniform(0.9f, 1.2f);
    const float z1 = std::min(z0 + rng->uniform(0.6f, 1.2f), ctx.ceiling_m - 0.15f);
    Item mirror = makeItem(kMirror, "mirror", tint(rng, 200, 210, 215, 12));
    mirror.parts.push_back(cuboid(0.0f, 0.0f, z0, w, 0.02f, z1));
    m.items.push_back(mirror);
  }
  m.end_margin_m = 0.1f;
  return m;
}

}  // namespace room
}  // namespace internal
}  // namespace panmap
