#pragma once

#include <cstdint>
#include <memory>
#include <set>
#include <vector>

#include "panmap/sim/internal/room_furniture.h"
#include "panmap/sim/internal/room_parts.h"
#include "panmap/sim/internal/room_random.h"
#include "panmap/sim/internal/room_shape.h"
#include "panmap/sim/procedural_room.h"

namespace panmap {
namespace internal {
namespace room {

/// One straight wall of the floor polygon.
struct WallSegment {
  Vector2f start;
  Vector2f along;   ///< unit, counter-clockwise around the room
  Vector2f inward;  ///< unit, into the room
  float length_m = 0.0f;
};

/// Places modules in a band of depth `band_m` along the walls (or in a central island zone),
/// keeps a corridor around the middle free of everything and keeps a share of the floor free
/// for a camera at walking heights (the constants are in room_layout.cpp).
class Layout {
 public:
  /// @param shape must outlive the layout.
  /// @param island whether to keep a zone in the middle of the first arm for a central table.
  Layout(const RoomShape& shape, float ceiling_m, float band_m, bool island);

  /// What builders may use: the band depth and the ceiling height.
  BuildContext context() const { return BuildContext{band_m_, ceiling_m_}; }
  /// True when the room has a central island zone.
  bool hasIslandZone() const { return !island_zone_.isEmpty(); }
  /// Everything placed so far, world frame.
  const std::vector<Item>& items() const { return items_; }

  /// Places the module (wall coordinates) at a random free position along a random wall;
  /// false when it fits nowhere.
  bool placeOnWall(RoomRng* rng, const Module& module);

  /// Places the module (normalised to start at the origin) turned by 0 or 90 degrees inside the
  /// island zone; false when it fits nowhere.
  bool placeIsland(RoomRng* rng, Module module);

  /// Places a loose item (world frame) as it is, when it rests on the floor or on the top of
  /// another item's box, keeps out of the walkway and the reserved boxes, overlaps no part of
  /// anything and either touches each part and wall near it or keeps a gap a sensor can see into
  /// (1 cm; cylinders always keep it from sides); false otherwise. Unlike modules, loose items
  /// may touch what is there.
  bool placeLoose(const Item& item);

  /// The floor plan.
  const RoomShape& shape() const { return shape_; }
  /// Ceiling height, metres.
  float ceilingM() const { return ceiling_m_; }
  /// The straight walls, counter-clockwise.
  const std::vector<WallSegment>& walls() const { return walls_; }

  /// The evaluated classes among the placed items.
  std::set<int32_t> evaluatedClassesPresent() const;

  /// The walkway: the cores (room minus the band) or, around an island, the ring of the core.
  std::vector<Box2> clearFloor() const;

 private:
  enum CellState : uint8_t { kOutside, kFree, kBlocked };

  /// Centre of free-space cell (i, j), world frame.
  Vector2f cellCentre(int i, int j) const;
  /// True when the module (world frame) is on the floor, under the ceiling, in the band (or the
  /// island zone) and clear of everything placed.
  bool fits(const Module& world, bool island) const;
  /// Cells a camera at walking heights could no longer use (closer than the clearance to an
  /// object's box), or false when too little free floor would be left.
  bool freeSpaceAfter(const Module& world, std::vector<int>* newly) const;
  /// Places the module (world frame) when it fits and leaves enough free floor.
  bool tryCommit(const Module& world, bool island);
  /// True when every lowest part of the item stands on the floor or on a box part's top.
  bool supported(const Item& item) const;
  /// True when a part's box neither overlaps anything placed (or a wall) nor leaves a slit;
  /// a cylinder (`cylinder`, or one placed before) keeps the gap from sides instead of touching.
  bool clearOf(const Box3& box, bool cylinder) const;

  const RoomShape& shape_;
  float ceiling_m_;
  float band_m_;
  std::vector<WallSegment> walls_;
  std::vector<Box2> core_;
  Box2 island_zone_;
  bool island_placed_ = false;
  std::vector<Item> items_;
  std::vector<Box3> blockers_;
  std::vector<Box3> reserved_;
  int cells_x_ = 0, cells_y_ = 0, floor_cells_ = 0, free_cells_ = 0;
  std::vector<uint8_t> state_;
};

/// Tries a few freshly drawn variants of a module (sizes differ) along the walls.
template <typename Build>
bool placeSome(Layout* layout, RoomRng* rng, Build build, int tries = 3) {
  for (int t = 0; t < tries; ++t) {
    if (layout->placeOnWall(rng, build())) return true;
  }
  return false;
}

/// One furnishing attempt: the compulsory groups (door, table with chairs, touching cabinets,
/// window), then optional ones until a drawn number of evaluated classes is present (box
/// rooms) or furnishScanNetLike's. nullptr when a compulsory group or `config.min_classes`
/// does not fit.
std::unique_ptr<Layout> furnish(const RoomShape& shape, float ceiling_m, const RoomConfig& config,
                                RoomRng* rng);

/// The furniture of a ScanNet-like room after the compulsory groups: optional groups until
/// `config.min_classes` evaluated classes are present, then a dresser, a wall shelf and a
/// whiteboard or mirror, then more optional groups while the room has fewer than 20 items,
/// boxes and 1-3 pictures. False when a picture or the classes do not fit.
bool furnishScanNetLike(Layout* layout, RoomRng* rng, const RoomConfig& config);

}  // namespace room
}  // namespace internal
}  // namespace panmap
