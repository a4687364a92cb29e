#pragma once

#include <cstdint>
#include <vector>

#include "panmap/core/labelled_mesh.h"
#include "panmap/sim/internal/room_parts.h"
#include "panmap/sim/internal/room_shape.h"

namespace panmap {
namespace internal {
namespace room {

/// Base colours of the stuff.
struct StuffColours {
  Rgb8 wall;
  Rgb8 floor;
  Rgb8 ceiling;
};

/// An opening in a wall from the floor up: a doorway to the next room or a corridor.
struct Doorway {
  int wall = 0;           ///< index of the polygon side from polygon[wall] to polygon[wall + 1]
  float from_m = 0.0f;    ///< distance along that side from its first corner, metres
  float to_m = 0.0f;      ///< > from_m
  float height_m = 0.0f;  ///< top of the opening, below the ceiling
};

/// Writes the room into `mesh`: walls (instance 1), floor (2), ceiling (3), then the items from
/// instance 4 in order, every triangle edge at most max_edge_m, faces nobody can see left out.
/// The walls have holes where `doorways` are (non-overlapping, inside their wall).
void writeRoomMesh(const RoomShape& shape, float ceiling_m, float max_edge_m,
                   const std::vector<Item>& items, const StuffColours& colours, LabelledMesh* mesh,
                   const std::vector<Doorway>& doorways = {});

/// The vertices items[first...] get in the room's mesh (the walls', floor's and ceiling's too
/// when first is 0): what writeRoomMesh would write for them, without writing the rest.
int64_t countVertices(const RoomShape& shape, float ceiling_m, float max_edge_m,
                      const std::vector<Item>& items, size_t first);

}  // namespace room
}  // namespace internal
}  // namespace panmap
