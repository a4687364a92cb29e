#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "panmap/sim/internal/room_mesh.h"
#include "panmap/sim/internal/room_parts.h"
#include "panmap/sim/internal/room_shape.h"
#include "panmap/sim/procedural_room.h"

namespace panmap {
namespace internal {
namespace room {

/// Changes a furnished room before its mesh is written: may edit, add or remove items (the
/// instances follow the edited order) and returns the doorways to cut into the walls.
using RoomEdit = std::function<std::vector<Doorway>(const RoomShape& shape, float ceiling_m,
                                                    std::vector<Item>*)>;

/// generateRoom with an edit between furnishing and meshing (a building opens each room's door
/// onto its corridor). A null edit gives exactly generateRoom's room.
ProceduralRoom generateEditedRoom(uint64_t seed, const RoomConfig& config, const RoomEdit& edit);

}  // namespace room
}  // namespace internal
}  // namespace panmap
