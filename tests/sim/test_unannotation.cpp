#include <algorithm>
#include <set>

#include <gtest/gtest.h>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/sim/unannotation.h"

namespace panmap {
namespace {

// A 4 m x 4 m floor grid (2 cm spacing) with 10 "things" as 0.4 m squares of it.
LabelledMesh floorWithThings() {
  LabelledMesh m;
  const int side = 201;
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      m.vertices.emplace_back(0.02f * x, 0.02f * y, 0.0f);
      int32_t cls = 2, inst = 1;
      const int cx = x / 40, cy = y / 40;
      if (x % 40 >= 10 && x % 40 < 30 && y % 40 >= 10 && y % 40 < 30 && cy < 2) {
        cls = 5;  // chair
        inst = 10 + cy * 5 + cx;
      }
      if (x < 3 && y < 3) cls = 0, inst = 0;  // a corner nobody annotated
      m.semantic.push_back(cls);
      m.instance.push_back(inst);
    }
  }
  for (int y = 0; y + 1 < side; ++y) {
    for (int x = 0; x + 1 < side; ++x) {
      const int a = y * side + x;
      m.faces.emplace_back(a, a + 1, a + side + 1);
      m.faces.emplace_back(a, a + side + 1, a + side);
    }
  }
  return m;
}

TEST(Unannotate, ZeroFractionOnlyTurnsClassZeroRegionsIntoClutterInstances) {
  const LabelledMesh mesh = floorWithThings();
  const UnannotatedMesh u = unannotate(mesh, UnannotateConfig(), 3);
  EXPECT_TRUE(u.stripped_instances.empty());
  EXPECT_EQ(u.clutter_patches, 0);
  EXPECT_EQ(u.clutter_instances, 1);  // the corner: one connected region
  EXPECT_EQ(u.ground_truth.semantic, mesh.semantic);
  EXPECT_EQ(u.ground_truth.instance, mesh.instance);
  EXPECT_EQ(u.world.semantic, mesh.semantic);
  EXPECT_EQ(u.world.instance[0], 20);  // above the largest id (19)
  EXPECT_NEAR(u.unannotated_fraction, 9.0 / mesh.numVertices(), 1e-12);
}

TEST(Unannotate, ReachesTheFractionWithWholeObjectsAndPatchesAndIsDeterministic) {
  const LabelledMesh mesh = floorWithThings();
  UnannotateConfig config;
  config.fraction = 0.2;
  const UnannotatedMesh u = unannotate(mesh, config, 7);
  const size_t n = mesh.numVertices();
  EXPECT_GE(u.unannotated_fraction, 0.2);
  EXPECT_LT(u.unannotated_fraction, 0.25);  // one patch at most past the target
  EXPECT_FALSE(u.stripped_instances.empty());
  EXPECT_GT(u.clutter_patches, 0);
  int64_t gt_zero = 0;
  for (size_t v = 0; v < n; ++v) {
    const bool stripped_object = std::binary_search(
        u.stripped_instances.begin(), u.stripped_instances.end(), mesh.instance[v]);
    if (stripped_object) {
      // Whole: every vertex of it left the GT; the world still knows it as a chair.
      EXPECT_EQ(u.ground_truth.semantic[v], 0);
      EXPECT_EQ(u.world.semantic[v], 5);
      EXPECT_EQ(u.world.instance[v], mesh.instance[v]);
    }
    if (u.ground_truth.semantic[v] == 0) {
      ++gt_zero;
      EXPECT_EQ(u.ground_truth.instance[v], 0);
      // Unannotated in GT: a stripped object or a class-0 clutter instance in the world.
      EXPECT_TRUE(stripped_object || (u.world.semantic[v] == 0 && u.world.instance[v] > 19));
    } else {
      EXPECT_EQ(u.ground_truth.semantic[v], mesh.semantic[v]);
      EXPECT_EQ(u.world.semantic[v], mesh.semantic[v]);
    }
  }
  EXPECT_NEAR(u.unannotated_fraction, static_cast<double>(gt_zero) / n, 1e-12);
  for (int32_t id : u.stripped_instances) EXPECT_GE(id, 10);  // never the floor (stuff)

  const UnannotatedMesh again = unannotate(mesh, config, 7);
  EXPECT_EQ(again.world.instance, u.world.instance);
  EXPECT_EQ(again.ground_truth.semantic, u.ground_truth.semantic);
  const UnannotatedMesh other = unannotate(mesh, config, 8);
  EXPECT_NE(other.ground_truth.semantic, u.ground_truth.semantic);
}

TEST(Unannotate, RefusesBadInput) {
  LabelledMesh mesh = floorWithThings();
  UnannotateConfig config;
  config.fraction = 1.0;
  EXPECT_THROW(unannotate(mesh, config, 1), Error);
  config.fraction = 0.1;
  config.patch_radius_max_m = 0.01f;
  EXPECT_THROW(unannotate(mesh, config, 1), Error);
  mesh.instance.clear();
  EXPECT_THROW(unannotate(mesh, UnannotateConfig(), 1), Error);
}

}  // namespace
}  // namespace panmap
