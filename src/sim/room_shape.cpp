#include "panmap/sim/internal/room_shape.h"

#include <algorithm>
#include <limits>

namespace panmap {
namespace internal {
namespace room {

bool RoomShape::containsRect(const Box2& r) const {
  if (r.min().x() < -kTolM || r.min().y() < -kTolM || r.max().x() > width_m + kTolM ||
      r.max().y() > depth_m + kTolM) {
    return false;
  }
  return !lShaped() || !overlaps2(r, notch, 0.0f);
}

float RoomShape::minArmM() const {
  float m = std::max(width_m, depth_m);
  for (const Box2& a : arms) m = std::min({m, a.sizes().x(), a.sizes().y()});
  return m;
}

float RoomShape::distanceToWalls(const Vector2f& p) const {
  float best = std::numeric_limits<float>::max();
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Vector2f a = polygon[i];
    const Vector2f ab = polygon[(i + 1) % polygon.size()] - a;
    const float t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0f, 1.0f);
    best = std::min(best, (a + t * ab - p).norm());
  }
  return best;
}

RoomShape drawShape(RoomRng* rng, const RoomConfig& config) {
  const bool want_l = rng->chance(config.l_shape_probability);
  const float l_min = std::max(config.min_width_m, 5.0f);
  const bool l_shape = want_l && config.max_width_m >= l_min;
  const float lo = l_shape ? l_min : config.min_width_m;
  RoomShape s;
  s.width_m = rng->uniform(lo, config.max_width_m);
  s.depth_m = rng->uniform(lo, config.max_width_m);
  const float w = s.width_m, d = s.depth_m;
  const Box2 all(Vector2f(0.0f, 0.0f), Vector2f(w, d));
  std::vector<Vector2f> corners = {{0.0f, 0.0f}, {w, 0.0f}, {w, d}, {0.0f, d}};
  if (!l_shape) {
    s.polygon = corners;
    s.arms = {all};
    s.tiles = {all};
    return s;
  }
  const int c = rng->uniformInt(0, 3);
  const float nx = rng->uniform(std::max(1.5f, 0.3f * w), std::min(w - 3.0f, 0.6f * w));
  const float ny = rng->uniform(std::max(1.5f, 0.3f * d), std::min(d - 3.0f, 0.6f * d));
  const bool high_x = c == 1 || c == 2;
  const bool high_y = c == 2 || c == 3;
  s.notch = Box2(Vector2f(high_x ? w - nx : 0.0f, high_y ? d - ny : 0.0f),
                 Vector2f(high_x ? w : nx, high_y ? d : ny));
  const Box2 arm_x(Vector2f(high_x ? 0.0f : nx, 0.0f), Vector2f(high_x ? w - nx : w, d));
  const Box2 arm_y(Vector2f(0.0f, high_y ? 0.0f : ny), Vector2f(w, high_y ? d - ny : d));
  s.arms = {arm_x, arm_y};
  s.tiles = {arm_x, Box2(Vector2f(s.notch.min().x(), arm_y.min().y()),
                         Vector2f(s.notch.max().x(), arm_y.max().y()))};
  // The cut corner becomes three vertices: the polygon stays counter-clockwise.
  const Vector2f corner = corners[c];
  const Vector2f to_prev = (corners[(c + 3) % 4] - corner).normalized();
  const Vector2f to_next = (corners[(c + 1) % 4] - corner).normalized();
  const Vector2f a = corner + to_prev * (to_prev.x() != 0.0f ? nx : ny);
  const Vector2f b = corner + to_next * (to_next.x() != 0.0f ? nx : ny);
  for (int i = 0; i < 4; ++i) {
    if (i != c) {
      s.polygon.push_back(corners[i]);
      continue;
    }
    // The inner corner copies coordinates rather than computing a + b - corner, which can be
    // off by an ulp and tilt the walls.
    s.polygon.push_back(a);
    s.polygon.push_back(
        Vector2f(a.x() != corner.x() ? a.x() : b.x(), a.y() != corner.y() ? a.y() : b.y()));
    s.polygon.push_back(b);
  }
  return s;
}

}  // namespace room
}  // namespace internal
}  // namespace panmap
