#include "panmap/sim/procedural_room.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fingerprint.h"
#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "room_checks.h"
#include "test_helpers.h"

namespace panmap {
namespace {

using Eigen::AlignedBox2f;
using Eigen::AlignedBox3f;
using Eigen::Vector2f;
using Eigen::Vector3f;
using test::bounds2;
using test::centroid;
using test::distanceToOutline;
using test::evaluatedIn;
using test::faceNormal;
using test::hasChairUnderTable;
using test::hasPictureOnWall;
using test::hasTouchingSameClassPair;
using test::insidePolygon;
using test::overlapVolume;
using test::signedArea;

constexpr int32_t kWallId = 1, kFloorId = 2, kCeilingId = 3;

/// Rooms of the default config, generated once per seed for the whole suite.
const ProceduralRoom& room(uint64_t seed) {
  static std::map<uint64_t, ProceduralRoom> cache;
  auto it = cache.find(seed);
  if (it == cache.end()) it = cache.emplace(seed, generateRoom(seed)).first;
  return it->second;
}

const std::vector<uint64_t> kSeeds = {1, 2, 3, 4, 5};

TEST(ProceduralRoom, SameSeedGivesIdenticalRoom) {
  const ProceduralRoom a = generateRoom(7);
  const ProceduralRoom b = generateRoom(7);
  ASSERT_EQ(a.mesh.numVertices(), b.mesh.numVertices());
  ASSERT_EQ(a.mesh.numFaces(), b.mesh.numFaces());
  EXPECT_TRUE(a.mesh.vertices == b.mesh.vertices);
  EXPECT_TRUE(a.mesh.faces == b.mesh.faces);
  EXPECT_EQ(a.mesh.semantic, b.mesh.semantic);
  EXPECT_EQ(a.mesh.instance, b.mesh.instance);
  EXPECT_TRUE(a.mesh.colors == b.mesh.colors);
  EXPECT_TRUE(a.floor_polygon == b.floor_polygon);
  EXPECT_EQ(a.ceiling_height_m, b.ceiling_height_m);
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].instance, b.objects[i].instance);
    EXPECT_EQ(a.objects[i].name, b.objects[i].name);
    EXPECT_TRUE(a.objects[i].box.min() == b.objects[i].box.min());
    EXPECT_TRUE(a.objects[i].box.max() == b.objects[i].box.max());
  }
  EXPECT_EQ(a.seed, 7u);
}

TEST(ProceduralRoom, BoxRoomsAreTheOnesResultsWereMeasuredOn) {
  // Fingerprints taken before room styles existed (x86-64, GCC 12; rooms are bit-exact per
  // platform only): docs/RESULTS.md and the other modules' tests depend on these rooms.
  EXPECT_EQ(test::fingerprint(room(1).mesh), 0x51385aa80c93206dull);
  EXPECT_EQ(test::fingerprint(room(2).mesh), 0x799f79106134d30full);
  EXPECT_EQ(test::fingerprint(room(3).mesh), 0x198d667d7347aefeull);
}

TEST(ProceduralRoom, DifferentSeedsGiveDifferentRooms) {
  for (size_t i = 0; i < kSeeds.size(); ++i) {
    for (size_t j = i + 1; j < kSeeds.size(); ++j) {
      const ProceduralRoom &a = room(kSeeds[i]), &b = room(kSeeds[j]);
      EXPECT_FALSE(a.floor_polygon == b.floor_polygon) << kSeeds[i] << " vs " << kSeeds[j];
      EXPECT_NE(a.mesh.numVertices(), b.mesh.numVertices());
    }
  }
}

TEST(ProceduralRoom, MeshIsConsistentAndLabelled) {
  for (uint64_t seed : kSeeds) {
    const LabelledMesh& m = room(seed).mesh;
    EXPECT_EQ(m.check(), "") << "seed " << seed;
    EXPECT_EQ(m.colors.size(), m.numVertices());
    EXPECT_EQ(m.semantic.size(), m.numVertices());
    EXPECT_EQ(m.instance.size(), m.numVertices());
    EXPECT_GT(m.numFaces(), 50000u);
    for (const Eigen::Vector3i& f : m.faces) {
      // Every triangle belongs to one object: its vertices share instance and class.
      ASSERT_EQ(m.instance[f[0]], m.instance[f[1]]);
      ASSERT_EQ(m.instance[f[0]], m.instance[f[2]]);
      const Vector3f& a = m.vertices[f[0]];
      ASSERT_GT((m.vertices[f[1]] - a).cross(m.vertices[f[2]] - a).norm(), 1e-10f);
    }
  }
}

TEST(ProceduralRoom, VerticesStayInsideTheRoom) {
  for (uint64_t seed : kSeeds) {
    const ProceduralRoom& r = room(seed);
    const AlignedBox2f floor = bounds2(r.floor_polygon);
    EXPECT_GE(floor.sizes().minCoeff(), 3.0f - 1e-4f);
    EXPECT_LE(floor.sizes().maxCoeff(), 9.0f + 1e-4f);
    EXPECT_GE(r.ceiling_height_m, 2.5f);
    EXPECT_LE(r.ceiling_height_m, 3.0f);
    for (const Vector3f& v : r.mesh.vertices) {
      ASSERT_TRUE(insidePolygon(r.floor_polygon, v.head<2>())) << v.transpose();
      ASSERT_GE(v.z(), -1e-5f);
      ASSERT_LE(v.z(), r.ceiling_height_m + 1e-5f);
    }
  }
}

TEST(ProceduralRoom, NoTriangleEdgeIsLongerThanMaxEdge) {
  auto longest = [](const LabelledMesh& m) {
    float worst = 0.0f;
    for (const Eigen::Vector3i& f : m.faces) {
      for (int k = 0; k < 3; ++k) {
        worst = std::max(worst, (m.vertices[f[k]] - m.vertices[f[(k + 1) % 3]]).norm());
      }
    }
    return worst;
  };
  for (uint64_t seed : kSeeds) EXPECT_LE(longest(room(seed).mesh), 0.05f + 1e-5f) << seed;
  RoomConfig coarse;
  coarse.max_edge_m = 0.12f;
  const ProceduralRoom r = generateRoom(1, coarse);
  EXPECT_LE(longest(r.mesh), 0.12f + 1e-5f);
  // Coarser edges, fewer triangles: about (0.05 / 0.12)^2 as many.
  EXPECT_LT(r.mesh.numFaces(), room(1).mesh.numFaces() / 4);
}

TEST(ProceduralRoom, EveryRoomHasTwelveEvaluatedClasses) {
  std::set<int32_t> all;
  for (uint64_t seed : kSeeds) {
    const std::set<int32_t> present = evaluatedIn(room(seed));
    EXPECT_GE(present.size(), 12u) << "seed " << seed;
    all.insert(present.begin(), present.end());
  }
  EXPECT_GE(all.size(), 16u);
}

TEST(ProceduralRoom, ObjectsMatchTheMeshLabels) {
  for (uint64_t seed : kSeeds) {
    const ProceduralRoom& r = room(seed);
    std::map<int32_t, const RoomObject*> by_id;
    for (const RoomObject& o : r.objects) {
      EXPECT_GT(o.instance, 0);
      EXPECT_TRUE(by_id.emplace(o.instance, &o).second) << "duplicate instance " << o.instance;
      EXPECT_FALSE(o.name.empty());
      EXPECT_EQ(o.parts.empty(), isStuffClass(o.semantic)) << o.name;
      for (const AlignedBox3f& p : o.parts) EXPECT_GT(p.sizes().minCoeff(), 0.0f) << o.name;
    }
    std::set<int32_t> seen;
    for (size_t v = 0; v < r.mesh.numVertices(); ++v) {
      const auto it = by_id.find(r.mesh.instance[v]);
      ASSERT_NE(it, by_id.end()) << "vertex instance " << r.mesh.instance[v] << " not listed";
      ASSERT_EQ(r.mesh.semantic[v], it->second->semantic) << it->second->name;
      AlignedBox3f grown = it->second->box;
      grown.extend(grown.min() - Vector3f::Constant(1e-4f));
      grown.extend(grown.max() + Vector3f::Constant(1e-4f));
      ASSERT_TRUE(grown.contains(r.mesh.vertices[v])) << it->second->name;
      seen.insert(r.mesh.instance[v]);
    }
    for (const RoomObject& o : r.objects) {
      EXPECT_TRUE(seen.count(o.instance)) << "seed " << seed << ": " << o.name << " has no vertex";
    }
    ASSERT_GE(r.objects.size(), 3u);
    EXPECT_EQ(r.objects[0].instance, kWallId);
    EXPECT_EQ(r.objects[0].semantic, 1);
    EXPECT_EQ(r.objects[1].instance, kFloorId);
    EXPECT_EQ(r.objects[1].semantic, 2);
    EXPECT_EQ(r.objects[2].instance, kCeilingId);
    EXPECT_EQ(r.objects[2].semantic, 22);
  }
}

TEST(ProceduralRoom, HardCasesArePresent) {
  for (uint64_t seed : kSeeds) {
    const ProceduralRoom& r = room(seed);
    EXPECT_TRUE(hasTouchingSameClassPair(r)) << "seed " << seed;
    EXPECT_TRUE(hasChairUnderTable(r)) << "seed " << seed;
    EXPECT_TRUE(hasPictureOnWall(r)) << "seed " << seed;
  }
}

TEST(ProceduralRoom, ObjectsOverlapOnlyWhereTheyRestInOneAnother) {
  // (inner, outer) classes allowed to share volume: a tucked chair and its table or desk, the
  // sink set into its counter, books in their shelf, pillows on a bed, a shower curtain
  // hanging into the tub.
  const std::set<std::pair<int32_t, int32_t>> allowed = {{5, 7},   {5, 14}, {34, 12},
                                                         {23, 10}, {18, 4}, {28, 36}};
  for (uint64_t seed : kSeeds) {
    const ProceduralRoom& r = room(seed);
    for (size_t i = 0; i < r.objects.size(); ++i) {
      for (size_t j = i + 1; j < r.objects.size(); ++j) {
        const RoomObject &a = r.objects[i], &b = r.objects[j];
        if (isStuffClass(a.semantic) || isStuffClass(b.semantic)) continue;
        if (overlapVolume(a.box, b.box) < 1e-6f) continue;
        EXPECT_TRUE(allowed.count({a.semantic, b.semantic}) ||
                    allowed.count({b.semantic, a.semantic}))
            << "seed " << seed << ": " << a.name << " overlaps " << b.name;
      }
    }
  }
}

TEST(ProceduralRoom, StuffSurfacesFaceIntoTheRoom) {
  for (uint64_t seed : kSeeds) {
    const ProceduralRoom& r = room(seed);
    EXPECT_GT(signedArea(r.floor_polygon), 0.0f) << "floor polygon is not counter-clockwise";
    int walls = 0;
    for (const Eigen::Vector3i& f : r.mesh.faces) {
      const int32_t id = r.mesh.instance[f[0]];
      const Vector3f n = faceNormal(r.mesh, f);
      if (id == kFloorId) {
        ASSERT_GT(n.z(), 0.999f);
      } else if (id == kCeilingId) {
        ASSERT_LT(n.z(), -0.999f);
      } else if (id == kWallId) {
        ASSERT_LT(std::abs(n.z()), 1e-3f);
        const Vector3f c = centroid(r.mesh, f);
        ASSERT_TRUE(insidePolygon(r.floor_polygon, (c + 0.01f * n).head<2>(), 0.0f));
        ASSERT_FALSE(insidePolygon(r.floor_polygon, (c - 0.01f * n).head<2>(), 0.0f));
        ++walls;
      }
    }
    EXPECT_GT(walls, 1000);
  }
}

TEST(ProceduralRoom, ObjectSurfacesFaceOutOfTheirParts) {
  // Just behind each triangle (against its normal) is the inside of one of its object's
  // boxes or cylinders; a flipped triangle would put that point outside.
  for (uint64_t seed : kSeeds) {
    const ProceduralRoom& r = room(seed);
    std::map<int32_t, const RoomObject*> by_id;
    for (const RoomObject& o : r.objects) by_id[o.instance] = &o;
    for (const Eigen::Vector3i& f : r.mesh.faces) {
      const RoomObject& o = *by_id.at(r.mesh.instance[f[0]]);
      if (isStuffClass(o.semantic)) continue;
      const Vector3f behind = centroid(r.mesh, f) - 1e-3f * faceNormal(r.mesh, f);
      const bool inside = std::any_of(o.parts.begin(), o.parts.end(),
                                      [&](const AlignedBox3f& p) { return p.contains(behind); });
      ASSERT_TRUE(inside) << "seed " << seed << ": " << o.name << " at " << behind.transpose();
    }
  }
}

TEST(ProceduralRoom, HiddenSurfacesAreLeftOut) {
  // No triangle lies flat against a box it cannot be seen past: the floor under a bed, the
  // wall behind a cabinet, a cabinet's side against its neighbour's. The triangle's centroid,
  // nudged along its normal, must not be 4 cm (more than a grid cell) inside a part's face.
  const std::set<int32_t> boxes_only = {3, 4, 6, 8, 9, 10, 11, 24, 36};
  for (uint64_t seed : kSeeds) {
    const ProceduralRoom& r = room(seed);
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
        ASSERT_FALSE(inner.contains(q)) << "seed " << seed << ": hidden triangle of instance "
                                        << r.mesh.instance[f[0]] << " at " << q.transpose();
      }
    }
  }
}

TEST(ProceduralRoom, CameraHasFreeSpace) {
  // Points at camera heights >= 0.3 m from every object box and wall, over >= 30 % of the floor.
  const float step = 0.05f, clearance = 0.3f;
  for (uint64_t seed : kSeeds) {
    const ProceduralRoom& r = room(seed);
    const AlignedBox2f floor = bounds2(r.floor_polygon);
    int inside = 0, free = 0;
    for (float y = floor.min().y() + 0.5f * step; y < floor.max().y(); y += step) {
      for (float x = floor.min().x() + 0.5f * step; x < floor.max().x(); x += step) {
        const Vector2f p(x, y);
        if (!insidePolygon(r.floor_polygon, p, 0.0f)) continue;
        ++inside;
        if (distanceToOutline(r.floor_polygon, p) < clearance) continue;
        bool ok = true;
        for (float z : {1.2f, 1.5f, 1.7f}) {
          for (const RoomObject& o : r.objects) {
            if (isStuffClass(o.semantic)) continue;
            if (o.box.exteriorDistance(Vector3f(x, y, z)) < clearance) ok = false;
          }
          ok = ok && r.ceiling_height_m - z >= clearance;
        }
        free += ok ? 1 : 0;
      }
    }
    EXPECT_GE(static_cast<double>(free), 0.3 * inside) << "seed " << seed;
  }
}

TEST(ProceduralRoom, ClearFloorIsAFreeWalkway) {
  for (uint64_t seed : kSeeds) {
    const ProceduralRoom& r = room(seed);
    ASSERT_FALSE(r.clear_floor.empty());
    for (const AlignedBox2f& c : r.clear_floor) {
      EXPECT_GE(c.sizes().minCoeff(), 0.9f - 1e-4f);
      for (const Vector2f& corner : {c.min(), c.max(), Vector2f(c.min().x(), c.max().y()),
                                     Vector2f(c.max().x(), c.min().y())}) {
        EXPECT_TRUE(insidePolygon(r.floor_polygon, corner));
      }
      for (const RoomObject& o : r.objects) {
        if (isStuffClass(o.semantic)) continue;
        const AlignedBox2f b(o.box.min().head<2>(), o.box.max().head<2>());
        const AlignedBox2f i = b.intersection(c);
        EXPECT_TRUE(i.isEmpty() || i.volume() == 0.0f) << "seed " << seed << ": " << o.name;
      }
    }
  }
}

TEST(ProceduralRoom, SmallAndLShapedRoomsKeepTheGuarantees) {
  RoomConfig small;
  small.min_width_m = small.max_width_m = 3.0f;
  RoomConfig l_shaped;
  l_shaped.l_shape_probability = 1.0f;
  for (uint64_t seed : {11, 12, 13}) {
    const ProceduralRoom s = generateRoom(seed, small);
    EXPECT_EQ(s.floor_polygon.size(), 4u);
    EXPECT_GE(evaluatedIn(s).size(), 12u);
    EXPECT_TRUE(hasTouchingSameClassPair(s));
    EXPECT_TRUE(hasChairUnderTable(s));
    const ProceduralRoom l = generateRoom(seed, l_shaped);
    ASSERT_EQ(l.floor_polygon.size(), 6u);
    EXPECT_GT(signedArea(l.floor_polygon), 0.0f);
    EXPECT_GE(evaluatedIn(l).size(), 12u);
    for (const Vector3f& v : l.mesh.vertices)
      ASSERT_TRUE(insidePolygon(l.floor_polygon, v.head<2>()));
  }
}

/// The message of the Error `config.check()` throws, or "" when it does not throw.
std::string checkMessage(const RoomConfig& config) {
  try {
    config.check();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ProceduralRoom, ConfigValidationNamesTheField) {
  EXPECT_EQ(checkMessage(RoomConfig()), "");
  struct Case {
    std::string field;
    void (*edit)(RoomConfig*);
  };
  const std::vector<Case> cases = {
      {"min_width_m", [](RoomConfig* c) { c->min_width_m = 0.0f; }},
      {"min_width_m", [](RoomConfig* c) { c->min_width_m = -3.0f; }},
      {"max_width_m", [](RoomConfig* c) { c->max_width_m = 2.5f; }},
      {"min_ceiling_m", [](RoomConfig* c) { c->min_ceiling_m = 0.0f; }},
      {"max_ceiling_m", [](RoomConfig* c) { c->max_ceiling_m = 2.4f; }},
      {"l_shape_probability", [](RoomConfig* c) { c->l_shape_probability = 1.5f; }},
      {"l_shape_probability", [](RoomConfig* c) { c->l_shape_probability = -0.1f; }},
      {"l_shape_probability", [](RoomConfig* c) { c->l_shape_probability = std::nanf(""); }},
      {"max_edge_m", [](RoomConfig* c) { c->max_edge_m = 0.0f; }},
      {"max_edge_m", [](RoomConfig* c) { c->max_edge_m = -0.05f; }},
      {"min_classes", [](RoomConfig* c) { c->min_classes = -1; }},
      {"min_classes", [](RoomConfig* c) { c->min_classes = 19; }},
  };
  for (const Case& c : cases) {
    RoomConfig config;
    c.edit(&config);
    const std::string message = checkMessage(config);
    EXPECT_EQ(message.rfind(c.field + ":", 0), 0u) << "'" << message << "'";
    EXPECT_EQ(message.find('\n'), std::string::npos);
    EXPECT_THROW(generateRoom(1, config), Error);
  }
  RoomConfig edge;
  edge.min_classes = 0;
  edge.min_width_m = edge.max_width_m = 4.0f;
  EXPECT_EQ(checkMessage(edge), "");
  EXPECT_NO_THROW(generateRoom(3, edge));
}

}  // namespace
}  // namespace panmap
