#pragma once

#include "panmap/sim/internal/room_parts.h"
#include "panmap/sim/internal/room_random.h"

namespace panmap {
namespace internal {
namespace room {

// The furniture catalogue. Every builder returns objects in wall coordinates (x along the wall,
// y into the room, z up, the wall at y = 0), or an empty module when it cannot fit in
// `max_depth_m`. Builders draw their sizes from `rng` in a fixed order: a seed's room depends
// on it.

/// What a builder may use of the room.
struct BuildContext {
  float max_depth_m = 0.0f;  ///< band depth available from the wall
  float ceiling_m = 0.0f;
};

/// A door proud of the wall, with a handle and its swing kept free.
Module buildDoor(RoomRng* rng, const BuildContext& ctx);

/// A window with a sill, with or without a curtain on each side.
Module buildWindow(RoomRng* rng, const BuildContext& ctx, bool curtains);

/// A picture hung around eye height.
Module buildPicture(RoomRng* rng, const BuildContext& ctx);

/// 2-4 cabinets side by side whose bodies touch: same-class instances without a depth edge.
Module buildCabinets(RoomRng* rng, const BuildContext& ctx);

/// A counter whose top has a hole the sink's basin sits in: the sink is inside the counter's box.
Module buildCounter(RoomRng* rng, const BuildContext& ctx);

/// A refrigerator with two doors and handles.
Module buildFridge(RoomRng* rng, const BuildContext& ctx);

/// An open bookshelf; each filled shelf carries one row of touching books (one instance).
Module buildBookshelf(RoomRng* rng, const BuildContext& ctx);

/// Head against the wall (single, double or two touching singles, with a night stand and lamp)
/// where the band is deep enough, else a single or double bed with its long side on the wall.
Module buildBed(RoomRng* rng, const BuildContext& ctx);

/// A bathtub with a hollow basin and a shower curtain hanging into it from a rod.
Module buildBath(RoomRng* rng, const BuildContext& ctx);

/// A toilet with its cistern against the wall.
Module buildToilet(RoomRng* rng, const BuildContext& ctx);

/// Class 39 clutter: a trash can, an ottoman or a bench.
Module buildOtherFurniture(RoomRng* rng, const BuildContext& ctx);

/// Two cardboard boxes, the smaller standing on the larger.
Module buildBoxes(RoomRng* rng, const BuildContext& ctx);

/// A table against the wall with chairs on the room side, the first tucked in so that its seat
/// is under the table top.
Module buildTableGroup(RoomRng* rng, const BuildContext& ctx);

/// A table in the middle of the room: chairs tucked in on one side, pulled out on the other.
/// Normalised to start at the origin; no wall.
Module buildIslandTableGroup(RoomRng* rng, bool end_chairs);

/// A desk with a monitor standing on it (and sometimes a box) and a chair half under it.
Module buildDesk(RoomRng* rng, const BuildContext& ctx);

/// A sofa against the wall, sometimes with a coffee table in front.
Module buildSofa(RoomRng* rng, const BuildContext& ctx);

/// A dresser with drawers, sometimes with a television standing on it.
Module buildDresser(RoomRng* rng, const BuildContext& ctx);

/// A shelf board on two brackets, hung on the wall between knee and head height.
Module buildWallShelf(RoomRng* rng, const BuildContext& ctx);

/// A whiteboard with a pen tray, or a mirror: flat objects on the wall like pictures.
Module buildWallBoard(RoomRng* rng, const BuildContext& ctx);

/// The optional groups a room may get, beyond the compulsory door, table, cabinets and window.
/// Box rooms draw from the first nine only; ScanNet-like rooms from all.
enum class Group {
  kCounter,
  kFridge,
  kDesk,
  kBookshelf,
  kSofa,
  kBed,
  kBath,
  kToilet,
  kOther,
  kDresser,
  kWallShelf,
  kWallBoard
};

/// Builds one optional group.
Module buildGroup(Group g, RoomRng* rng, const BuildContext& ctx);

}  // namespace room
}  // namespace internal
}  // namespace panmap
