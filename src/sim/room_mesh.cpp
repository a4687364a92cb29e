#include "panmap/sim/internal/room_mesh.h"

#include <algorithm>
#include <limits>
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

// The part of the wall from a to b between s0 and s1 metres along it and heights z0 to z1.
void addWallPiece(const Vector2f& a, const Vector2f& b, float s0, float s1, float z0, float z1,
                  MeshWriter* writer) {
  const float length = (b - a).norm();
  // Exact corners where the piece reaches them: no ulp-sized slit at the room's corners.
  const Vector2f p = s0 <= 0.0f ? a : a + (b - a) * (s0 / length);
  const Vector2f q = s1 >= length ? b : a + (b - a) * (s1 / length);
  // z x (b - a) is the inward normal of a counter-clockwise outline.
  writer->addRect({p.x(), p.y(), z0}, {p.x(), p.y(), z1}, {q.x(), q.y(), z0}, -1);
}

void writeStuff(const RoomShape& shape, float h, const StuffColours& colours,
                const std::vector<Doorway>& doorways, MeshWriter* writer) {
  writer->setLabel(1, kWall, colours.wall);
  for (size_t i = 0; i < shape.polygon.size(); ++i) {
    const Vector2f a = shape.polygon[i];
    const Vector2f b = shape.polygon[(i + 1) % shape.polygon.size()];
    std::vector<Doorway> holes;
    for (const Doorway& d : doorways) {
      if (d.wall == static_cast<int>(i)) holes.push_back(d);
    }
    std::sort(holes.begin(), holes.end(),
              [](const Doorway& x, const Doorway& y) { return x.from_m < y.from_m; });
    float s = 0.0f;
    for (const Doorway& d : holes) {
      if (d.from_m > s) addWallPiece(a, b, s, d.from_m, 0.0f, h, writer);
      addWallPiece(a, b, d.from_m, d.to_m, d.height_m, h, writer);
      s = d.to_m;
    }
    addWallPiece(a, b, s, std::numeric_limits<float>::max(), 0.0f, h, writer);
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
                   const std::vector<Item>& items, const StuffColours& colours, LabelledMesh* mesh,
                   const std::vector<Doorway>& doorways) {
  MeshWriter writer(shape, ceiling_m, max_edge_m, solidsOf(items), mesh);
  writeStuff(shape, ceiling_m, colours, doorways, &writer);
  writeItems(items, 0, &writer);
}

int64_t countVertices(const RoomShape& shape, float ceiling_m, float max_edge_m,
                      const std::vector<Item>& items, size_t first) {
  LabelledMesh scratch;
  MeshWriter writer(shape, ceiling_m, max_edge_m, solidsOf(items), &scratch);
  if (first == 0) writeStuff(shape, ceiling_m, StuffColours(), {}, &writer);
  writeItems(items, first, &writer);
  return static_cast<int64_t>(scratch.numVertices());
}

}  // namespace room
}  // namespace internal
}  // namespace panmap
