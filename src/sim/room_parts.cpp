#include "panmap/sim/internal/room_parts.h"

#include <algorithm>

namespace panmap {
namespace internal {
namespace room {

Part cuboid(float x0, float y0, float z0, float x1, float y1, float z1) {
  return Part{Box3(Vector3f(x0, y0, z0), Vector3f(x1, y1, z1)), false};
}

Part cylinder(float cx, float cy, float r, float z0, float z1) {
  return Part{Box3(Vector3f(cx - r, cy - r, z0), Vector3f(cx + r, cy + r, z1)), true};
}

Box3 rotateQuarter(const Box3& b, int quarter_turns) {
  const int k = ((quarter_turns % 4) + 4) % 4;
  auto rot = [k](float x, float y) {
    switch (k) {
      case 1:
        return Vector2f(-y, x);
      case 2:
        return Vector2f(-x, -y);
      case 3:
        return Vector2f(y, -x);
      default:
        return Vector2f(x, y);
    }
  };
  const Vector2f a = rot(b.min().x(), b.min().y());
  const Vector2f c = rot(b.max().x(), b.max().y());
  return Box3(Vector3f(std::min(a.x(), c.x()), std::min(a.y(), c.y()), b.min().z()),
              Vector3f(std::max(a.x(), c.x()), std::max(a.y(), c.y()), b.max().z()));
}

Item makeItem(int32_t semantic, const char* name, const Rgb8& color) {
  Item item;
  item.semantic = semantic;
  item.name = name;
  item.color = color;
  return item;
}

bool overlaps2(const Box2& a, const Box2& b, float gap) {
  return a.min().x() < b.max().x() + gap && b.min().x() < a.max().x() + gap &&
         a.min().y() < b.max().y() + gap && b.min().y() < a.max().y() + gap;
}

bool overlaps3(const Box3& a, const Box3& b, float gap) {
  for (int k = 0; k < 3; ++k) {
    if (!(a.min()[k] < b.max()[k] + gap && b.min()[k] < a.max()[k] + gap)) return false;
  }
  return true;
}

Box2 xy(const Box3& b) { return Box2(b.min().head<2>(), b.max().head<2>()); }

Box2 eroded(const Box2& b, float d) {
  return Box2(b.min() + Vector2f::Constant(d), b.max() - Vector2f::Constant(d));
}

}  // namespace room
}  // namespace internal
}  // namespace panmap
