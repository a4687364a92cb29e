#pragma once

#include "panmap/sim/internal/room_layout.h"
#include "panmap/sim/internal/room_random.h"

namespace panmap {
namespace internal {
namespace room {

/// What a ScanNet-like room must reach; addLooseObjects fails below it.
constexpr int kMinInstances = 30;         ///< annotated instances, stuff included
constexpr int kMaxInstances = 60;         ///< all instances, unannotated clutter included
constexpr int kMinClasses = 15;           ///< distinct NYU40 classes, stuff included
constexpr double kMinUnannotated = 0.05;  ///< share of the mesh's vertices in class 0

/// Adds the loose objects of a ScanNet-like room to a furnished layout (room_loose_items.h):
/// things on tables, desks, counters, shelves, beds and sofas, some pushed to an edge against a
/// wall; things on desks against the monitor's foot; clutter on the floor against furniture and
/// walls; then unannotated piles, on the floor against walls and furniture or on tops, until a
/// drawn 6-8.5 % of the vertices (estimated by meshing, max_edge_m as the room's) are class 0.
/// False when the room ends outside the targets above (the caller draws another layout).
bool addLooseObjects(Layout* layout, RoomRng* rng, float max_edge_m);

}  // namespace room
}  // namespace internal
}  // namespace panmap
