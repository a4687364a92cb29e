#include "panmap/sim/procedural_room.h"

#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/core/random.h"
#include "panmap/sim/internal/room_clutter.h"
#include "panmap/sim/internal/room_edit.h"
#include "panmap/sim/internal/room_layout.h"
#include "panmap/sim/internal/room_mesh.h"
#include "panmap/sim/internal/room_parts.h"
#include "panmap/sim/internal/room_random.h"
#include "panmap/sim/internal/room_shape.h"

namespace panmap {

namespace {

using Eigen::Vector3f;
using internal::room::addLooseObjects;
using internal::room::Box3;
using internal::room::drawShape;
using internal::room::furnish;
using internal::room::Item;
using internal::room::kCeiling;
using internal::room::kFloor;
using internal::room::kWall;
using internal::room::Layout;
using internal::room::Part;
using internal::room::RoomRng;
using internal::room::RoomShape;
using internal::room::StuffColours;
using internal::room::tint;
using internal::room::writeRoomMesh;

constexpr int kMaxAttempts = 40;

std::string metres(float v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

void RoomConfig::check() const {
  auto fail = [](const std::string& field, const std::string& why, float value) {
    throw Error(field + ": " + why + ", got " + metres(value));
  };
  if (!(min_width_m >= 2.0f)) fail("min_width_m", "must be at least 2 m", min_width_m);
  if (!(max_width_m >= min_width_m)) fail("max_width_m", "must be >= min_width_m", max_width_m);
  if (!(max_width_m <= 30.0f)) fail("max_width_m", "must be at most 30 m", max_width_m);
  if (!(min_ceiling_m >= 2.3f)) {
    fail("min_ceiling_m", "must be at least 2.3 m (doors, shower curtains)", min_ceiling_m);
  }
  if (!(max_ceiling_m >= min_ceiling_m)) {
    fail("max_ceiling_m", "must be >= min_ceiling_m", max_ceiling_m);
  }
  if (!(max_ceiling_m <= 10.0f)) fail("max_ceiling_m", "must be at most 10 m", max_ceiling_m);
  if (!(l_shape_probability >= 0.0f && l_shape_probability <= 1.0f)) {
    fail("l_shape_probability", "must be in [0, 1]", l_shape_probability);
  }
  if (!(max_edge_m > 0.0f)) fail("max_edge_m", "must be > 0", max_edge_m);
  if (!(max_edge_m >= 0.005f)) {
    fail("max_edge_m", "must be at least 0.005 m (finer meshes are too large)", max_edge_m);
  }
  const int n = static_cast<int>(evaluatedClasses().size());
  if (min_classes < 0 || min_classes > n) {
    throw Error("min_classes: must be in [0, " + std::to_string(n) + "], got " +
                std::to_string(min_classes));
  }
}

RoomConfig RoomConfig::scanNetLike() {
  RoomConfig config;
  config.min_width_m = 4.0f;
  config.max_width_m = 8.0f;
  config.style = RoomStyle::kScanNetLike;
  return config;
}

ProceduralRoom generateRoom(uint64_t seed, const RoomConfig& config) {
  return internal::room::generateEditedRoom(seed, config, nullptr);
}

namespace internal {
namespace room {

ProceduralRoom generateEditedRoom(uint64_t seed, const RoomConfig& config, const RoomEdit& edit) {
  config.check();
  const bool scannet = config.style == RoomStyle::kScanNetLike;
  // The floor plan depends on the seed alone; furnishing retries draw from their own streams.
  RoomRng shape_rng(splitmix64(seed));
  const RoomShape shape = drawShape(&shape_rng, config);
  const float ceiling_m = shape_rng.uniform(config.min_ceiling_m, config.max_ceiling_m);
  std::unique_ptr<Layout> layout;
  uint64_t stream = 0;
  for (int attempt = 0; attempt < kMaxAttempts && !layout; ++attempt) {
    stream = splitmix64(seed ^ splitmix64(0xF0123456789ull + static_cast<uint64_t>(attempt)));
    RoomRng rng(stream);
    layout = furnish(shape, ceiling_m, config, &rng);
    if (layout && scannet && !addLooseObjects(layout.get(), &rng, config.max_edge_m)) {
      layout.reset();
    }
  }
  if (!layout) {
    const std::string what =
        scannet ? " evaluated classes (or a ScanNet-like room's instances)" : " evaluated classes";
    throw Error("min_classes: " + std::to_string(config.min_classes) + what +
                " do not fit in the " + metres(shape.width_m) + " x " + metres(shape.depth_m) +
                " m room of seed " + std::to_string(seed));
  }
  RoomRng colour_rng(splitmix64(stream + 1));

  ProceduralRoom room;
  room.seed = seed;
  room.ceiling_height_m = ceiling_m;
  room.floor_polygon = shape.polygon;
  room.clear_floor = layout->clearFloor();
  // Separate statements: the order of the draws is part of the room a seed gives.
  StuffColours colours;
  colours.wall = tint(&colour_rng, 225, 220, 210, 25);
  colours.floor = tint(&colour_rng, 150, 115, 80, 40);
  colours.ceiling = tint(&colour_rng, 240, 240, 238, 8);
  std::vector<Item> items = layout->items();
  const std::vector<Doorway> doorways =
      edit ? edit(shape, ceiling_m, &items) : std::vector<Doorway>();
  writeRoomMesh(shape, ceiling_m, config.max_edge_m, items, colours, &room.mesh, doorways);

  const float w = shape.width_m, d = shape.depth_m, h = ceiling_m;
  room.objects.push_back(
      RoomObject{1, kWall, "wall", Box3(Vector3f::Zero(), Vector3f(w, d, h)), {}});
  room.objects.push_back(
      RoomObject{2, kFloor, "floor", Box3(Vector3f::Zero(), Vector3f(w, d, 0.0f)), {}});
  room.objects.push_back(
      RoomObject{3, kCeiling, "ceiling", Box3(Vector3f(0.0f, 0.0f, h), Vector3f(w, d, h)), {}});
  int32_t instance = 4;
  for (const Item& item : items) {
    RoomObject object{instance, item.semantic, item.name, item.bounds(), {}};
    for (const Part& p : item.parts) object.parts.push_back(p.box);
    room.objects.push_back(std::move(object));
    ++instance;
  }
  return room;
}

}  // namespace room
}  // namespace internal
}  // namespace panmap
