#pragma once

#include <vector>

#include "panmap/sim/internal/room_parts.h"
#include "panmap/sim/internal/room_random.h"
#include "panmap/sim/procedural_room.h"

namespace panmap {
namespace internal {
namespace room {

/// The floor plan: a rectangle, or an L (a rectangle minus one corner), z up from the floor.
struct RoomShape {
  float width_m = 0.0f;  ///< bounding rectangle [0, W] x [0, D]
  float depth_m = 0.0f;
  Box2 notch;                     ///< the corner cut out of an L (empty for a rectangle)
  std::vector<Box2> arms;         ///< maximal rectangles, their union is the floor
  std::vector<Box2> tiles;        ///< disjoint rectangles, their union is the floor
  std::vector<Vector2f> polygon;  ///< counter-clockwise

  /// True for an L, false for a rectangle.
  bool lShaped() const { return !notch.isEmpty(); }
  /// True when p is on the floor, grown by `tol` (inline: the hidden-face test asks per sample).
  bool contains(const Vector2f& p, float tol) const {
    if (p.x() < -tol || p.y() < -tol || p.x() > width_m + tol || p.y() > depth_m + tol) {
      return false;
    }
    if (!lShaped()) return true;
    return !(p.x() > notch.min().x() + tol && p.x() < notch.max().x() - tol &&
             p.y() > notch.min().y() + tol && p.y() < notch.max().y() - tol);
  }
  /// True when the rectangle lies on the floor (up to kTolM).
  bool containsRect(const Box2& r) const;
  /// The narrowest side of any arm, metres.
  float minArmM() const;
  /// Distance from p to the nearest wall, metres.
  float distanceToWalls(const Vector2f& p) const;
};

/// Draws a floor plan: rectangles of sides in [min_width_m, max_width_m]; an L cuts a corner
/// off a rectangle of sides >= 5 m so that both arms stay at least 3 m wide.
RoomShape drawShape(RoomRng* rng, const RoomConfig& config);

}  // namespace room
}  // namespace internal
}  // namespace panmap
