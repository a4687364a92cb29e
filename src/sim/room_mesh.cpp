#include "panmap/sim/internal/room_mesh.h"

#include <vector>

#include "panmap/sim/internal/room_geometry.h"

namespace panmap {
namespace internal {
namespace room {
namespace {

std::vector<Solid> solidsOf(const std::vector<Item>& items) {
  std::vector<Solid> solids;
  for (const Item& item : items) {
    for (const Part& p : item.parts) solids.push_back(Solid{p.box, p.cylinder});
  }
  return solids;
}

void writeStuff(const RoomShape& shape, float h, const StuffColours& colours, MeshWriter* writer) {
  writer->setLabel(1, kWall, colours.wall);
  for (size_t i = 0; i < shape.polygon.size(); ++i) {
    const Vector2f a = shape.polygon[i];
    const Vector2f b = shape.polygon[(i + 1) % shape.polygon.size()];
    // z x (b - a) is the inward normal of a counter-clockwise outline.
    writer->addRect({a.x(), a.y(), 0.0f}, {a.x(), a.y(), h}, {b.x(), b.y(), 0.0f}, -1);
  }
  writer->setLabel(2, kFloor, colours.floor);
  for (const Box2& t : shape.tiles) {
    const Vector2f a = t.min(), b = t.max();
    writer->addRect({a.x(), a.y(), 0.0f}, {b.x(), a.y(), 0.0f}, {a.x(), b.y(), 0.0f}, -1);
  }
  writer->setLabel(3, kCeiling, colours.ceiling);
  for (const Box2& t : shape.tiles) {
    const Vector2f a = t.min(), b = t.max();
    writer->addRect({a.x(), a.y(), h}, {a.x(), b.y(), h}, {b.x(), a.y(), h}, -1);
  }
}

// Writes items[first...]; solid indices count the parts of the items before them too.
void writeItems(const std::vector<Item>& items, size_t first, MeshWriter* writer) {
  int solid = 0;
  int32_t instance = 4;
  for (size_t i = 0; i < items.size(); ++i, ++instance) {
    const Item& item = items[i];
    if (i < first) {
      solid += static_cast<int>(item.parts.size());
      continue;
    }
    writer->setLabel(instance, item.semantic, item.color);
    for (const Part& p : item.parts) {
      if (p.cylinder) {
        writer->addCylinder(p.box, solid);
      } else {
        writer->addBox(p.box, solid);
      }
      ++solid;
    }
  }
}

}  // namespace

void writeRoomMesh(const RoomShape& shape, float ceiling_m, float max_edge_m,
                   const std::vector<Item>& items, const StuffColours& colours,
                   LabelledMesh* mesh) {
  MeshWriter writer(shape, ceiling_m, max_edge_m, solidsOf(items), mesh);
  writeStuff(shape, ceiling_m, colours, &writer);
  writeItems(items, 0, &writer);
}

int64_t countVertices(const RoomShape& shape, float ceiling_m, float max_edge_m,
                      const std::vector<Item>& items, size_t first) {
  LabelledMesh scratch;
  MeshWriter writer(shape, ceiling_m, max_edge_m, solidsOf(items), &scratch);
  if (first == 0) writeStuff(shape, ceiling_m, StuffColours(), &writer);
  writeItems(items, first, &writer);
  return static_cast<int64_t>(scratch.numVertices());
}

}  // namespace room
}  // namespace internal
}  // namespace panmap
