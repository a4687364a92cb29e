#pragma once

#include <cstdint>

#include "panmap/sim/internal/room_parts.h"
#include "panmap/sim/internal/room_random.h"

namespace panmap {
namespace internal {
namespace room {

// The catalogue of loose objects of ScanNet-like rooms. Every builder returns one item in local
// coordinates with its bounds' minimum at the origin, standing on z = 0; its back (the face that
// goes against a wall or a piece of furniture) is y = 0. Sizes are drawn from `rng` in a fixed
// order: a seed's room depends on it.

/// Something put down on a surface of an item of class `support` (a table, desk, counter,
/// cabinet, shelf, bed, sofa ...): books, a box, a bottle, a cup, a laptop, paper, a lamp, a
/// towel, clothes, a cushion. Mostly under 0.3 m.
Item buildSurfaceObject(RoomRng* rng, int32_t support);

/// Like buildSurfaceObject, but always small (under 0.3 m): books, a box, a bottle, a cup,
/// paper, a towel.
Item buildSmallObject(RoomRng* rng, int32_t support);

/// Something put down on the floor against a wall or furniture: a bag, a box, shoes, a picture
/// leaning there, a plant, a trash can, clothes, a stack of books.
Item buildFloorObject(RoomRng* rng);

/// Like buildFloorObject, but always small (under 0.3 m): a box, shoes, books, a bag.
Item buildSmallFloorObject(RoomRng* rng);

/// Something on a desk next to its monitor: a keyboard, a mouse, books, paper (nothing round:
/// cylinders keep a gap from sides).
Item buildDeskObject(RoomRng* rng);

/// Unannotated clutter (class 0): an irregular pile of 4-8 boxes and cylinders stacked on and
/// pushed against one another, at most `max_side_m` across and `max_height_m` high.
Item buildPile(RoomRng* rng, float max_side_m, float max_height_m);

/// Small: the largest side of the item's bounds is under 0.3 m.
bool isSmall(const Item& item);

}  // namespace room
}  // namespace internal
}  // namespace panmap
