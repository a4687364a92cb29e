#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/sim/instance_parts.h"

namespace panmap {
namespace {

// Adds a horizontal rectangle of vertices on a 1 cm grid, nx_cm by ny_cm from (x0, y0) at
// height z, all of one class and instance. Corners sit half a centimetre off the footprint
// grid's lines, so that no vertex lies on a cell boundary.
void addRect(LabelledMesh* mesh, float x0, float y0, float z, int nx_cm, int ny_cm, int32_t cls,
             int32_t instance) {
  for (int i = 0; i < nx_cm; ++i) {
    for (int j = 0; j < ny_cm; ++j) {
      mesh->vertices.emplace_back(x0 + 0.01f * i, y0 + 0.01f * j, z);
      mesh->semantic.push_back(cls);
      mesh->instance.push_back(instance);
    }
  }
}

int32_t instanceAt(const LabelledMesh& mesh, float x, float y, float z) {
  for (size_t v = 0; v < mesh.numVertices(); ++v) {
    if ((mesh.vertices[v] - Eigen::Vector3f(x, y, z)).norm() < 1e-4f) return mesh.instance[v];
  }
  return -1;
}

TEST(JoinStackedParts, AChairBaseUnderItsSeatJoinsTheSeat) {
  LabelledMesh mesh;
  addRect(&mesh, 0.005f, 0.005f, 0.5f, 50, 50, 5, 7);      // seat: 10 x 10 cells of 5 cm
  addRect(&mesh, 0.055f, 0.055f, 0.1f, 40, 40, 5, 9);      // its base: 8 x 8 cells under it
  addRect(&mesh, 2.005f, 0.005f, 0.5f, 50, 50, 5, 3);      // another chair, elsewhere
  addRect(&mesh, -0.995f, -0.995f, 0.0f, 300, 300, 2, 1);  // the floor under all of them
  const auto joins = joinStackedParts(&mesh, PartJoinConfig());
  ASSERT_EQ(joins.size(), 1u);
  EXPECT_EQ(joins[0].part, 9);
  EXPECT_EQ(joins[0].into, 7);
  EXPECT_EQ(joins[0].class_id, 5);
  EXPECT_DOUBLE_EQ(joins[0].share, 1.0);
  EXPECT_EQ(instanceAt(mesh, 0.055f, 0.055f, 0.1f), 7);
  EXPECT_EQ(instanceAt(mesh, 2.005f, 0.005f, 0.5f), 3);
  EXPECT_EQ(instanceAt(mesh, -0.995f, -0.995f, 0.0f), 1);  // stuff is never joined
}

TEST(JoinStackedParts, OtherClassesAndSmallOverlapsStayApart) {
  PartJoinConfig config;
  config.cell_m = 0.1f;
  LabelledMesh mesh;
  addRect(&mesh, 0.005f, 0.005f, 0.7f, 100, 100, 7, 4);  // a table: 10 x 10 cells
  addRect(&mesh, 0.205f, 0.205f, 0.45f, 40, 40, 5, 5);   // a chair under it: another class
  // A second table, 5 x 5 cells, one column of them (x 0.9-1.0 m) under the first: share 0.2.
  addRect(&mesh, 0.905f, 0.005f, 0.7f, 50, 50, 7, 6);
  EXPECT_TRUE(joinStackedParts(&mesh, config).empty());
  config.min_share = 0.2;
  const auto joins = joinStackedParts(&mesh, config);
  ASSERT_EQ(joins.size(), 1u);
  EXPECT_EQ(joins[0].part, 6);
  EXPECT_EQ(joins[0].into, 4);
  EXPECT_DOUBLE_EQ(joins[0].share, 0.2);
  EXPECT_EQ(instanceAt(mesh, 0.205f, 0.205f, 0.45f), 5);
}

TEST(JoinStackedParts, AChainResolvesToItsRoot) {
  LabelledMesh mesh;
  addRect(&mesh, 0.005f, 0.005f, 0.6f, 60, 60, 5, 10);  // seat: cells x 0-11, y 0-11
  addRect(&mesh, 0.305f, 0.005f, 0.3f, 50, 50, 5, 11);  // cells x 6-15, y 0-9: 0.6 under 10
  addRect(&mesh, 0.605f, 0.005f, 0.1f, 20, 20, 5, 12);  // cells x 12-15, y 0-3: only under 11
  const auto joins = joinStackedParts(&mesh, PartJoinConfig());
  ASSERT_EQ(joins.size(), 2u);
  EXPECT_EQ(joins[0].part, 11);
  EXPECT_EQ(joins[0].into, 10);
  EXPECT_DOUBLE_EQ(joins[0].share, 0.6);
  EXPECT_EQ(joins[1].part, 12);
  EXPECT_EQ(joins[1].into, 10);
  EXPECT_DOUBLE_EQ(joins[1].share, 1.0);
  EXPECT_EQ(instanceAt(mesh, 0.795f, 0.195f, 0.1f), 10);
}

TEST(JoinStackedParts, APieceBetweenTwoChairsJoinsTheOneOverMostOfIt) {
  LabelledMesh mesh;
  addRect(&mesh, 0.005f, 0.005f, 0.6f, 60, 60, 5, 10);  // chair A: cells x 0-11
  addRect(&mesh, 0.805f, 0.005f, 0.6f, 60, 60, 5, 20);  // chair B: cells x 16-27
  // Cells x 9-20, y 0-3 (48): 12 under A, 20 under B.
  addRect(&mesh, 0.455f, 0.005f, 0.2f, 60, 20, 5, 30);
  const auto joins = joinStackedParts(&mesh, PartJoinConfig());
  ASSERT_EQ(joins.size(), 1u);
  EXPECT_EQ(joins[0].part, 30);
  EXPECT_EQ(joins[0].into, 20);
  EXPECT_DOUBLE_EQ(joins[0].share, 20.0 / 48.0);
  EXPECT_EQ(instanceAt(mesh, 0.005f, 0.005f, 0.6f), 10);
  EXPECT_EQ(instanceAt(mesh, 0.805f, 0.005f, 0.6f), 20);
}

TEST(JoinStackedParts, RefusesAMeshWithoutLabelsAndABadConfig) {
  LabelledMesh mesh;
  mesh.vertices.emplace_back(0.0f, 0.0f, 0.0f);
  EXPECT_THROW(joinStackedParts(&mesh, PartJoinConfig()), Error);
  mesh.semantic.push_back(5);
  mesh.instance.push_back(1);
  PartJoinConfig config;
  config.min_share = 0.0;
  EXPECT_THROW(joinStackedParts(&mesh, config), Error);
  config = PartJoinConfig();
  config.cell_m = -1.0f;
  EXPECT_THROW(joinStackedParts(&mesh, config), Error);
  EXPECT_TRUE(joinStackedParts(&mesh, PartJoinConfig()).empty());
  // One instance id on a chair vertex and a table vertex: not a segGroup's instance.
  mesh.vertices.emplace_back(1.0f, 0.0f, 0.0f);
  mesh.semantic.push_back(7);
  mesh.instance.push_back(1);
  EXPECT_THROW(joinStackedParts(&mesh, PartJoinConfig()), Error);
}

}  // namespace
}  // namespace panmap
