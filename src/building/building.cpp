#include "panmap/building/building.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "panmap/core/error.h"
#include "panmap/core/random.h"
#include "panmap/sim/internal/room_edit.h"
#include "panmap/sim/internal/room_geometry.h"

namespace panmap {

namespace {

using Eigen::AlignedBox2f;
using Eigen::Vector2f;
using Eigen::Vector3f;
using internal::room::Box2;
using internal::room::Box3;
using internal::room::Doorway;
using internal::room::Frame;
using internal::room::Item;
using internal::room::MeshWriter;
using internal::room::RoomShape;
using internal::room::StuffColours;

// A room's door as the edit found it: the opening in the room's own frame.
struct DoorSpec {
  Doorway doorway;
  Vector2f start = Vector2f::Zero();  // first corner of the door's wall
  Vector2f along = Vector2f::UnitX();
  Vector2f inward = Vector2f::UnitY();
};

// Unit directions along and into the room of side `wall` of a rectangle's outline
// (0,0) -> (W,0) -> (W,D) -> (0,D).
void wallFrame(const RoomShape& shape, int wall, DoorSpec* spec) {
  const Vector2f a = shape.polygon[wall];
  const Vector2f b = shape.polygon[(wall + 1) % shape.polygon.size()];
  spec->start = a;
  spec->along = (b - a).normalized();
  spec->inward = Vector2f(-spec->along.y(), spec->along.x());
}

// Width of the way a walker needs past a door's open panel, metres.
constexpr float kWayM = 0.6f;

// Whether the walker can pass through the strip [s_lo, s_hi] x [t_lo, t_hi] of a wall frame
// (s along the wall, t into the room): it lies on the room's floor and no item other than the
// door stands in it below head height.
bool wayOpen(const RoomShape& shape, const std::vector<Item>& items, const Item& door,
             const Frame& frame, float s_lo, float s_hi, float t_lo, float t_hi) {
  constexpr float kHeadM = 2.0f;
  const Box2 strip = internal::room::xy(
      frame.apply(Box3(Vector3f(s_lo, t_lo, 0.0f), Vector3f(s_hi, t_hi, kHeadM))));
  if (!shape.containsRect(strip)) return false;
  for (const Item& item : items) {
    if (&item == &door) continue;
    for (const internal::room::Part& part : item.parts) {
      if (part.box.min().z() < kHeadM &&
          internal::room::overlaps2(internal::room::xy(part.box), strip, 0.0f)) {
        return false;
      }
    }
  }
  return true;
}

// Opens the room's door (class door, the compulsory one): the panel turns 90 degrees on its
// hinge into its swing, which the room keeps free, and the wall behind it becomes a doorway.
std::vector<Doorway> openDoor(const RoomShape& shape, std::vector<Item>* items, DoorSpec* spec) {
  Item* door = nullptr;
  for (Item& item : *items) {
    if (item.semantic == internal::room::kDoor && item.name == "door" && !item.parts.empty()) {
      door = &item;
      break;
    }
  }
  if (!door) throw Error("building: a room has no door (room generator changed?)");
  const Box3 panel = door->parts[0].box;
  const Box3 handle = door->parts.size() > 1 ? door->parts[1].box : panel;
  const Vector3f size = panel.sizes();
  constexpr float kTol = 1e-3f;
  int wall = -1;
  if (size.y() < size.x() && panel.min().y() < kTol) {
    wall = 0;
  } else if (size.x() < size.y() && panel.max().x() > shape.width_m - kTol) {
    wall = 1;
  } else if (size.y() < size.x() && panel.max().y() > shape.depth_m - kTol) {
    wall = 2;
  } else if (size.x() < size.y() && panel.min().x() < kTol) {
    wall = 3;
  }
  if (wall < 0) throw Error("building: a room's door does not stand against a wall");
  wallFrame(shape, wall, spec);
  const float sa = (panel.min().head<2>() - spec->start).dot(spec->along);
  const float sb = (panel.max().head<2>() - spec->start).dot(spec->along);
  const float s0 = std::min(sa, sb), s1 = std::max(sa, sb);
  const float width = s1 - s0, thick = std::min(size.x(), size.y());
  const float height = panel.max().z();
  const float s_handle = (handle.center().head<2>() - spec->start).dot(spec->along);
  bool hinge_at_end = s_handle < 0.5f * (s0 + s1);
  // Wall frame: x along the wall from its first corner, y into the room.
  const Frame frame{spec->start, spec->along, spec->inward};
  // The room keeps the swing free, not a way out of it: furniture just beyond the swing and a
  // corner on its open side would leave the open panel closing a pocket (ScanNet-like building
  // seed 15: a door by a corner, two beds in front). Such a door is hung the other way, as a
  // builder would, when the way past its other side is free; every other door keeps the
  // handle's side, so buildings that had a way in stay as they were.
  if (!wayOpen(shape, *items, *door, frame, s0, s1, width, width + kWayM)) {
    const bool start_open = wayOpen(shape, *items, *door, frame, s0 - kWayM, s0, 0.0f, width);
    const bool end_open = wayOpen(shape, *items, *door, frame, s1, s1 + kWayM, 0.0f, width);
    if (hinge_at_end && !start_open && end_open) hinge_at_end = false;
    if (!hinge_at_end && !end_open && start_open) hinge_at_end = true;
  }
  const float p0 = hinge_at_end ? s1 - thick : s0, p1 = hinge_at_end ? s1 : s0 + thick;
  const float h0 = hinge_at_end ? p0 - 0.05f : p1, h1 = hinge_at_end ? p0 : p1 + 0.05f;
  door->parts[0].box =
      frame.apply(Box3(Vector3f(p0, 0.0f, panel.min().z()), Vector3f(p1, width, panel.max().z())));
  if (door->parts.size() > 1) {
    door->parts[1].box = frame.apply(Box3(Vector3f(h0, width - 0.18f, handle.min().z()),
                                          Vector3f(h1, width - 0.06f, handle.max().z())));
  }
  spec->doorway = Doorway{wall, s0, s1, height};
  return {spec->doorway};
}

// A rigid move of a room into the building: q quarter turns about z, then a shift.
struct Placement {
  int quarters = 0;
  Vector2f shift = Vector2f::Zero();

  Vector2f apply(Vector2f p) const {
    for (int k = 0; k < quarters; ++k) p = Vector2f(-p.y(), p.x());
    return p + shift;
  }
  Vector3f apply(const Vector3f& p) const {
    const Vector2f q = apply(Vector2f(p.head<2>()));
    return Vector3f(q.x(), q.y(), p.z());
  }
  AlignedBox2f apply(const AlignedBox2f& b) const {
    AlignedBox2f out(apply(b.min()));
    out.extend(apply(b.max()));
    return out;
  }
  Box3 apply(const Box3& b) const {
    Box3 out(apply(b.min()));
    out.extend(apply(b.max()));
    return out;
  }
};

// Appends src to dst, moved by `place`, instance i > 0 renumbered to first + i - 1.
void appendMesh(const LabelledMesh& src, const Placement& place, int32_t first, LabelledMesh* dst) {
  const auto base = static_cast<int32_t>(dst->vertices.size());
  for (size_t v = 0; v < src.vertices.size(); ++v) {
    dst->vertices.push_back(place.apply(src.vertices[v]));
    dst->colors.push_back(src.colors.empty() ? Rgb8{180, 180, 180} : src.colors[v]);
    dst->semantic.push_back(src.semantic.empty() ? 0 : src.semantic[v]);
    const int32_t id = src.instance.empty() ? 0 : src.instance[v];
    dst->instance.push_back(id > 0 ? first + id - 1 : 0);
  }
  for (const Eigen::Vector3i& f : src.faces) {
    dst->faces.push_back(f + Eigen::Vector3i::Constant(base));
  }
}

// A rectangle as a room outline.
RoomShape rectangle(float width_m, float depth_m) {
  RoomShape shape;
  shape.width_m = width_m;
  shape.depth_m = depth_m;
  const Box2 all(Vector2f::Zero(), Vector2f(width_m, depth_m));
  shape.polygon = {{0.0f, 0.0f}, {width_m, 0.0f}, {width_m, depth_m}, {0.0f, depth_m}};
  shape.arms = {all};
  shape.tiles = {all};
  return shape;
}

// The faces inside a doorway's wall slab (world x0..x1, y0..y1, up to height): both jambs and
// the lintel with the wall's label, the threshold with the floor's.
void writeDoorSlab(float x0, float x1, float y0, float y1, float height, float max_edge_m,
                   int32_t wall_id, const Rgb8& wall_colour, int32_t floor_id,
                   const Rgb8& floor_colour, LabelledMesh* mesh) {
  // A writer over a box around the slab with no solids hides nothing of it.
  const Vector2f origin(x0 - 0.5f, y0 - 0.5f);
  const float w = x1 - x0, t = y1 - y0;
  LabelledMesh local;
  const RoomShape around = rectangle(w + 1.0f, t + 1.0f);  // the writer keeps a reference
  MeshWriter writer(around, height + 1.0f, max_edge_m, {}, &local);
  const float a = 0.5f, b = 0.5f + w, c = 0.5f, d = 0.5f + t;
  writer.setLabel(wall_id, internal::room::kWall, wall_colour);
  writer.addRect({a, c, 0.0f}, {a, d, 0.0f}, {a, c, height}, -1);      // faces +x
  writer.addRect({b, c, 0.0f}, {b, c, height}, {b, d, 0.0f}, -1);      // faces -x
  writer.addRect({a, c, height}, {a, d, height}, {b, c, height}, -1);  // faces down
  writer.setLabel(floor_id, internal::room::kFloor, floor_colour);
  writer.addRect({a, c, 0.0f}, {b, c, 0.0f}, {a, d, 0.0f}, -1);  // faces up
  Placement shift;
  shift.shift = origin;
  appendMesh(local, shift, 1, mesh);  // labels are building ids already: first = 1 keeps them
}

// Colour of the first vertex with this instance.
Rgb8 colourOf(const LabelledMesh& mesh, int32_t instance) {
  for (size_t v = 0; v < mesh.instance.size(); ++v) {
    if (mesh.instance[v] == instance && !mesh.colors.empty()) return mesh.colors[v];
  }
  return Rgb8{180, 180, 180};
}

}  // namespace

void BuildingConfig::check() const {
  if (min_rooms < 1)
    throw Error("building min_rooms must be >= 1, got " + std::to_string(min_rooms));
  if (max_rooms < min_rooms) throw Error("building max_rooms must be >= min_rooms");
  if (!(min_floor_area_m2 >= 0.0)) throw Error("building min_floor_area_m2 must be >= 0");
  if (!(corridor_width_m >= 1.5f)) throw Error("building corridor_width_m must be >= 1.5 m");
  if (!(corridor_ceiling_m >= 2.3f)) throw Error("building corridor_ceiling_m must be >= 2.3 m");
  if (!(wall_thickness_m >= 0.05f && wall_thickness_m <= 1.0f)) {
    throw Error("building wall_thickness_m must be in [0.05, 1] m");
  }
  room.check();
}

RoomConfig BuildingConfig::defaultRoom() {
  RoomConfig room;
  room.min_width_m = 4.0f;
  room.max_width_m = 9.0f;
  return room;
}

Building generateBuilding(uint64_t seed, const BuildingConfig& config) {
  config.check();
  RoomConfig room_config = config.room;
  room_config.l_shape_probability = 0.0f;
  const float corridor_w = config.corridor_width_m, wall_t = config.wall_thickness_m;

  Building building;
  LabelledMesh& mesh = building.mesh;
  float cursor[2] = {0.0f, 0.0f};  // next free x along the north and the south row
  double area = 0.0;
  int32_t next_id = 4;  // the corridor's walls, floor and ceiling are 1, 2, 3
  std::vector<Doorway> corridor_doors[2];
  std::vector<std::pair<float, size_t>> order;  // door centre x, room index
  for (int r = 0; r < config.max_rooms; ++r) {
    if (r >= config.min_rooms && area >= config.min_floor_area_m2) break;
    const bool north = r % 2 == 0;
    const uint64_t room_seed = hashSeed(seed, 0xB1D9u, static_cast<uint64_t>(r));
    DoorSpec door;
    const ProceduralRoom room = internal::room::generateEditedRoom(
        room_seed, room_config, [&door](const RoomShape& shape, float, std::vector<Item>* items) {
          return openDoor(shape, items, &door);
        });
    // Turn the door's wall to face the corridor: its inward normal points +y for a north room.
    const int normal_quarter = door.inward.x() > 0.5f    ? 0
                               : door.inward.y() > 0.5f  ? 1
                               : door.inward.x() < -0.5f ? 2
                                                         : 3;
    Placement place;
    place.quarters = ((north ? 1 : 3) - normal_quarter + 4) % 4;
    const float w = room.floor_polygon[2].x(), d = room.floor_polygon[2].y();
    const AlignedBox2f turned = place.apply(AlignedBox2f(Vector2f::Zero(), Vector2f(w, d)));
    const float x = cursor[north ? 0 : 1];
    place.shift = Vector2f(x - turned.min().x(), north ? corridor_w + wall_t - turned.min().y()
                                                       : -wall_t - turned.max().y());
    cursor[north ? 0 : 1] = x + turned.sizes().x() + wall_t;

    BuildingRoom info;
    info.seed = room_seed;
    info.north = north;
    info.floor = place.apply(AlignedBox2f(Vector2f::Zero(), Vector2f(w, d)));
    for (const auto& b : room.clear_floor) info.clear_floor.push_back(place.apply(b));
    info.first_instance = next_id;
    int32_t max_local = 0;
    for (const RoomObject& o : room.objects) max_local = std::max(max_local, o.instance);
    info.last_instance = next_id + max_local - 1;
    appendMesh(room.mesh, place, next_id, &mesh);
    for (const RoomObject& o : room.objects) {
      RoomObject moved = o;
      moved.instance = next_id + o.instance - 1;
      moved.box = place.apply(o.box);
      for (auto& p : moved.parts) p = place.apply(p);
      building.objects.push_back(std::move(moved));
    }
    // The doorway through the wall, world frame.
    const Vector2f pa = place.apply(Vector2f(door.start + door.doorway.from_m * door.along));
    const Vector2f pb = place.apply(Vector2f(door.start + door.doorway.to_m * door.along));
    const float x0 = std::min(pa.x(), pb.x()), x1 = std::max(pa.x(), pb.x());
    const float y0 = north ? corridor_w : -wall_t, y1 = north ? corridor_w + wall_t : 0.0f;
    info.door = AlignedBox2f(Vector2f(x0, y0), Vector2f(x1, y1));
    writeDoorSlab(x0, x1, y0, y1, door.doorway.height_m, room_config.max_edge_m, next_id,
                  colourOf(room.mesh, 1), next_id + 1, colourOf(room.mesh, 2), &mesh);
    corridor_doors[north ? 0 : 1].push_back(Doorway{0, x0, x1, door.doorway.height_m});
    order.push_back({0.5f * (x0 + x1), building.rooms.size()});
    next_id += max_local;
    area += static_cast<double>(w) * d;
    building.rooms.push_back(std::move(info));
  }
  if (area < config.min_floor_area_m2 ||
      static_cast<int>(building.rooms.size()) < config.min_rooms) {
    throw Error("building: " + std::to_string(config.max_rooms) +
                " rooms (max_rooms) do not reach " + std::to_string(config.min_floor_area_m2) +
                " m2 (min_floor_area_m2)");
  }

  // The corridor: as long as the longer row; its south wall (side 0, from x = 0) opens onto
  // the south rooms, its north wall (side 2, from x = length backwards) onto the north rooms.
  const float length = std::max(cursor[0], cursor[1]) - wall_t;
  std::vector<Doorway> doors = corridor_doors[1];
  for (const Doorway& n : corridor_doors[0]) {
    doors.push_back(Doorway{2, length - n.to_m, length - n.from_m, n.height_m});
  }
  const float corridor_h = config.corridor_ceiling_m;
  for (const Doorway& d : doors) {
    if (d.height_m >= corridor_h)
      throw Error("building corridor_ceiling_m must be above the doors");
  }
  LabelledMesh corridor;
  StuffColours colours;
  colours.wall = Rgb8{205, 200, 190};
  colours.floor = Rgb8{110, 112, 118};
  colours.ceiling = Rgb8{238, 238, 235};
  internal::room::writeRoomMesh(rectangle(length, corridor_w), corridor_h, room_config.max_edge_m,
                                {}, colours, &corridor, doors);
  appendMesh(corridor, Placement(), 1, &mesh);
  building.corridor = AlignedBox2f(Vector2f::Zero(), Vector2f(length, corridor_w));
  building.objects.insert(
      building.objects.begin(),
      {RoomObject{1,
                  internal::room::kWall,
                  "wall",
                  Box3(Vector3f::Zero(), Vector3f(length, corridor_w, corridor_h)),
                  {}},
       RoomObject{2,
                  internal::room::kFloor,
                  "floor",
                  Box3(Vector3f::Zero(), Vector3f(length, corridor_w, 0.0f)),
                  {}},
       RoomObject{3,
                  internal::room::kCeiling,
                  "ceiling",
                  Box3(Vector3f(0.0f, 0.0f, corridor_h), Vector3f(length, corridor_w, corridor_h)),
                  {}}});
  building.floor_area_m2 = area + static_cast<double>(length) * corridor_w;

  // Rooms in the order a walk along the corridor passes their doors.
  std::stable_sort(order.begin(), order.end());
  std::vector<BuildingRoom> sorted;
  for (const auto& [x, index] : order) sorted.push_back(building.rooms[index]);
  building.rooms = std::move(sorted);
  const std::string problem = mesh.check();
  if (!problem.empty()) throw Error("building: mesh is inconsistent: " + problem);
  return building;
}

}  // namespace panmap
