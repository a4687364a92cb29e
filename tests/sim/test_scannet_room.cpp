// ScanNet-like procedural rooms (RoomStyle::kScanNetLike): what they add to box rooms, and
// that they keep every convention box rooms keep.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/classes.h"
#include "panmap/sim/procedural_room.h"
#include "room_checks.h"

namespace panmap {
namespace {

using Eigen::AlignedBox2f;
using Eigen::AlignedBox3f;
using Eigen::Vector2f;
using Eigen::Vector3f;
using test::bounds2;
using test::boxGap;
using test::centroid;
using test::distanceToOutline;
using test::evaluatedIn;
using test::faceNormal;
using test::insidePolygon;
using test::overlapVolume;
using test::rectToOutline;

constexpr int32_t kUnannotated = 0, kMonitorClass = 40;

/// ScanNet-like rooms, generated once per seed for the whole suite.
const ProceduralRoom& room(uint64_t seed) {
  static std::map<uint64_t, ProceduralRoom> cache;
  auto it = cache.find(seed);
  if (it == cache.end())
    it = cache.emplace(seed, generateRoom(seed, RoomConfig::scanNetLike())).first;
  return it->second;
}

/// Loose things: what clutter is made of (a leaning picture, books, boxes, bags, props, class 0).
bool loose(int32_t c) {
  return c == kUnannotated || c == 11 || c == 21 || c == 23 || c == 29 || c == 37 || c == 39 ||
         c == 40;
}

/// Furniture standing on the floor that clutter is pushed against.
bool furniture(int32_t c) {
  static const std::set<int32_t> kFurniture = {3, 4, 5, 6, 7, 10, 12, 14, 17, 24, 32, 33, 36};
  return kFurniture.count(c) > 0;
}

/// Smallest distance between the parts of two objects.
float partGap(const RoomObject& a, const RoomObject& b) {
  float best = 1e9f;
  for (const AlignedBox3f& p : a.parts) {
    for (const AlignedBox3f& q : b.parts) best = std::min(best, boxGap(p, q));
  }
  return best;
}

/// The object whose part top `o` rests on (its lowest point on that top, its footprint over it);
/// nullptr for none (on the floor, or hanging).
const RoomObject* supportOf(const ProceduralRoom& r, const RoomObject& o) {
  const float z0 = o.box.min().z();
  for (const RoomObject& other : r.objects) {
    if (other.instance == o.instance) continue;
    for (const AlignedBox3f& q : other.parts) {
      if (std::abs(q.max().z() - z0) > 1e-4f) continue;
      const AlignedBox2f top(q.min().head<2>(), q.max().head<2>());
      const AlignedBox2f foot(o.box.min().head<2>(), o.box.max().head<2>());
      if (!top.intersection(foot).isEmpty() && top.intersection(foot).volume() > 0.0f) {
        return &other;
      }
    }
  }
  return nullptr;
}

class ScanNetRoom : public ::testing::TestWithParam<uint64_t> {};

TEST(ScanNetRoomStyle, SameSeedGivesIdenticalRoom) {
  const ProceduralRoom a = generateRoom(12, RoomConfig::scanNetLike());
  const ProceduralRoom& b = room(12);
  EXPECT_TRUE(a.mesh.vertices == b.mesh.vertices);
  EXPECT_TRUE(a.mesh.faces == b.mesh.faces);
  EXPECT_EQ(a.mesh.semantic, b.mesh.semantic);
  EXPECT_EQ(a.mesh.instance, b.mesh.instance);
  EXPECT_TRUE(a.mesh.colors == b.mesh.colors);
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) EXPECT_EQ(a.objects[i].name, b.objects[i].name);
  // The style changes the furniture, not the floor plan a seed gives.
  RoomConfig boxes = RoomConfig::scanNetLike();
  boxes.style = RoomStyle::kBoxes;
  EXPECT_TRUE(generateRoom(12, boxes).floor_polygon == a.floor_polygon);
  EXPECT_NE(generateRoom(12, boxes).mesh.numVertices(), a.mesh.numVertices());
}

TEST_P(ScanNetRoom, HasScanNetsInstancesClassesAndUnannotatedShare) {
  const ProceduralRoom& r = room(GetParam());
  int annotated = 0, clutter = 0;
  std::set<int32_t> classes;
  std::set<int32_t> clutter_ids;
  for (const RoomObject& o : r.objects) {
    if (o.semantic == kUnannotated) {
      ++clutter;
      clutter_ids.insert(o.instance);
      EXPECT_EQ(o.name, "clutter");
      EXPECT_FALSE(o.parts.empty());
    } else {
      ++annotated;
      classes.insert(o.semantic);
    }
  }
  EXPECT_GE(annotated, 30);
  EXPECT_LE(static_cast<int>(r.objects.size()), 60);
  EXPECT_GE(classes.size(), 15u);
  EXPECT_GE(evaluatedIn(r).size(), 12u);
  EXPECT_GE(clutter, 3);
  size_t zero = 0;
  for (size_t v = 0; v < r.mesh.numVertices(); ++v) {
    if (r.mesh.semantic[v] != kUnannotated) continue;
    ++zero;
    // Each pile is an instance of its own, as unannotated clutter is in panmap-synth's world.
    ASSERT_TRUE(clutter_ids.count(r.mesh.instance[v])) << r.mesh.instance[v];
  }
  const double share = static_cast<double>(zero) / static_cast<double>(r.mesh.numVertices());
  EXPECT_GE(share, 0.03);
  EXPECT_LE(share, 0.12);
  RecordProperty("annotated_instances", annotated);
  RecordProperty("clutter_instances", clutter);
  RecordProperty("classes", static_cast<int>(classes.size()));
  RecordProperty("unannotated_share", std::to_string(share));
}

TEST_P(ScanNetRoom, HasSmallObjectsOnSurfacesAndOnTheFloor) {
  const ProceduralRoom& r = room(GetParam());
  int small = 0, on_floor = 0, on_surfaces = 0;
  std::set<int32_t> supports;
  for (const RoomObject& o : r.objects) {
    if (o.semantic == kUnannotated || isStuffClass(o.semantic)) continue;
    if (o.box.sizes().maxCoeff() >= 0.3f) continue;
    ++small;
    if (o.box.min().z() <= 1e-4f) {
      ++on_floor;
    } else if (const RoomObject* s = supportOf(r, o)) {
      ++on_surfaces;
      supports.insert(s->semantic);
    }
  }
  EXPECT_GE(small, 10);
  EXPECT_GE(on_floor, 1);
  EXPECT_GE(on_surfaces, 6);
  EXPECT_GE(supports.size(), 3u);  // tables, desks, counters, cabinets, shelves, beds ...
  RecordProperty("small_objects", small);
}

TEST_P(ScanNetRoom, ClutterTouchesFurnitureWallsAndMonitors) {
  const ProceduralRoom& r = room(GetParam());
  int at_furniture = 0, at_walls = 0;
  for (const RoomObject& o : r.objects) {
    if (!loose(o.semantic) || o.parts.empty() || o.box.min().z() > 1e-4f) continue;
    const AlignedBox2f foot(o.box.min().head<2>(), o.box.max().head<2>());
    at_walls += rectToOutline(r.floor_polygon, foot) <= 0.01f ? 1 : 0;
    for (const RoomObject& f : r.objects) {
      if (furniture(f.semantic) && partGap(o, f) <= 0.01f) {
        ++at_furniture;
        break;
      }
    }
  }
  EXPECT_GE(at_furniture, 3);
  EXPECT_GE(at_walls, 3);
  // Things on a desk against the monitor's foot.
  for (const RoomObject& m : r.objects) {
    if (m.name != "monitor" || m.semantic != kMonitorClass) continue;
    int touching = 0;
    for (const RoomObject& o : r.objects) {
      if (o.instance != m.instance && o.semantic != 14 && partGap(o, m) <= 1e-3f) ++touching;
    }
    EXPECT_GE(touching, 1) << "monitor " << m.instance;
  }
  RecordProperty("clutter_at_furniture", at_furniture);
  RecordProperty("clutter_at_walls", at_walls);
}

TEST_P(ScanNetRoom, KeepsTheHardCases) {
  const ProceduralRoom& r = room(GetParam());
  EXPECT_TRUE(test::hasTouchingSameClassPair(r));
  EXPECT_TRUE(test::hasChairUnderTable(r));
  EXPECT_TRUE(test::hasPictureOnWall(r));
}

TEST_P(ScanNetRoom, MeshKeepsTheConventions) {
  const ProceduralRoom& r = room(GetParam());
  const LabelledMesh& m = r.mesh;
  ASSERT_EQ(m.check(), "");
  std::map<int32_t, const RoomObject*> by_id;
  for (const RoomObject& o : r.objects) ASSERT_TRUE(by_id.emplace(o.instance, &o).second);
  std::set<int32_t> seen;
  for (size_t v = 0; v < m.numVertices(); ++v) {
    const Vector3f& p = m.vertices[v];
    ASSERT_TRUE(insidePolygon(r.floor_polygon, p.head<2>())) << p.transpose();
    ASSERT_GE(p.z(), -1e-5f);
    ASSERT_LE(p.z(), r.ceiling_height_m + 1e-5f);
    const auto it = by_id.find(m.instance[v]);
    ASSERT_NE(it, by_id.end());
    ASSERT_EQ(m.semantic[v], it->second->semantic);
    AlignedBox3f grown = it->second->box;
    grown.extend(grown.min() - Vector3f::Constant(1e-4f));
    grown.extend(grown.max() + Vector3f::Constant(1e-4f));
    ASSERT_TRUE(grown.contains(p)) << it->second->name;
    seen.insert(m.instance[v]);
  }
  for (const RoomObject& o : r.objects) EXPECT_TRUE(seen.count(o.instance)) << o.name;
  for (const Eigen::Vector3i& f : m.faces) {
    ASSERT_EQ(m.instance[f[0]], m.instance[f[1]]);
    ASSERT_EQ(m.instance[f[0]], m.instance[f[2]]);
    for (int k = 0; k < 3; ++k) {
      ASSERT_LE((m.vertices[f[k]] - m.vertices[f[(k + 1) % 3]]).norm(), 0.05f + 1e-5f);
    }
    // Surfaces face out of their parts.
    const RoomObject& o = *by_id.at(m.instance[f[0]]);
    if (o.parts.empty()) continue;
    const Vector3f behind = centroid(m, f) - 1e-3f * faceNormal(m, f);
    ASSERT_TRUE(std::any_of(o.parts.begin(), o.parts.end(),
                            [&](const AlignedBox3f& p) { return p.contains(behind); }))
        << o.name << " at " << behind.transpose();
  }
}

TEST_P(ScanNetRoom, HiddenSurfacesAreLeftOut) {
  // As for box rooms: no triangle lies flat against a box it cannot be seen past, which here
  // includes the sides of clutter pushed against furniture and walls.
  const std::set<int32_t> boxes_only = {3, 4, 6, 8, 9, 10, 11, 17, 24, 36};
  const ProceduralRoom& r = room(GetParam());
  std::vector<AlignedBox3f> parts;
  for (const RoomObject& o : r.objects) {
    if (boxes_only.count(o.semantic)) parts.insert(parts.end(), o.parts.begin(), o.parts.end());
  }
  for (const Eigen::Vector3i& f : r.mesh.faces) {
    const Vector3f n = faceNormal(r.mesh, f);
    const Vector3f q = centroid(r.mesh, f) + 0.005f * n;
    int axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    for (const AlignedBox3f& p : parts) {
      Vector3f shrink = Vector3f::Constant(0.04f);
      shrink[axis] = 0.0f;
      const AlignedBox3f inner(p.min() + shrink, p.max() - shrink);
      ASSERT_FALSE(inner.contains(q))
          << "hidden triangle of instance " << r.mesh.instance[f[0]] << " at " << q.transpose();
    }
  }
}

TEST_P(ScanNetRoom, ObjectsTouchButNeverOverlap) {
  // Clutter may touch anything; no part of one object may be inside another's.
  const ProceduralRoom& r = room(GetParam());
  for (size_t i = 0; i < r.objects.size(); ++i) {
    for (size_t j = i + 1; j < r.objects.size(); ++j) {
      const RoomObject &a = r.objects[i], &b = r.objects[j];
      for (const AlignedBox3f& p : a.parts) {
        for (const AlignedBox3f& q : b.parts) {
          ASSERT_LT(overlapVolume(p, q), 1e-6f) << a.name << " overlaps " << b.name;
        }
      }
    }
  }
}

TEST_P(ScanNetRoom, WalkwayAndCameraSpaceStayFree) {
  const ProceduralRoom& r = room(GetParam());
  ASSERT_FALSE(r.clear_floor.empty());
  for (const AlignedBox2f& c : r.clear_floor) {
    EXPECT_GE(c.sizes().minCoeff(), 0.9f - 1e-4f);
    for (const RoomObject& o : r.objects) {
      if (isStuffClass(o.semantic)) continue;
      const AlignedBox2f i =
          AlignedBox2f(o.box.min().head<2>(), o.box.max().head<2>()).intersection(c);
      EXPECT_TRUE(i.isEmpty() || i.volume() == 0.0f) << o.name;
    }
  }
  // Points at camera heights >= 0.3 m from every object box and wall, over >= 30 % of the floor.
  const float step = 0.05f, clearance = 0.3f;
  const AlignedBox2f floor = bounds2(r.floor_polygon);
  int inside = 0, free = 0;
  for (float y = floor.min().y() + 0.5f * step; y < floor.max().y(); y += step) {
    for (float x = floor.min().x() + 0.5f * step; x < floor.max().x(); x += step) {
      if (!insidePolygon(r.floor_polygon, Vector2f(x, y), 0.0f)) continue;
      ++inside;
      if (distanceToOutline(r.floor_polygon, Vector2f(x, y)) < clearance) continue;
      bool ok = true;
      for (float z : {1.2f, 1.5f, 1.7f}) {
        for (const RoomObject& o : r.objects) {
          if (!isStuffClass(o.semantic) && o.box.exteriorDistance(Vector3f(x, y, z)) < clearance)
            ok = false;
        }
      }
      free += ok ? 1 : 0;
    }
  }
  EXPECT_GE(static_cast<double>(free), 0.3 * inside);
}

INSTANTIATE_TEST_SUITE_P(Seeds, ScanNetRoom, ::testing::Values(1, 2, 3, 11, 12, 13, 21, 22));

}  // namespace
}  // namespace panmap
