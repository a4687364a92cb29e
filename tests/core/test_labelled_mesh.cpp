#include <gtest/gtest.h>

#include "panmap/core/labelled_mesh.h"

namespace panmap {
namespace {

TEST(LabelledMesh, SurfaceAreaOfAUnitSquareAndATriangle) {
  LabelledMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 2}};
  mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_DOUBLE_EQ(mesh.surfaceArea(), 1.0);
  mesh.faces.push_back({0, 1, 4});  // right triangle with legs 1 and 2, upright
  EXPECT_DOUBLE_EQ(mesh.surfaceArea(), 2.0);
  EXPECT_DOUBLE_EQ(LabelledMesh().surfaceArea(), 0.0);
}

}  // namespace
}  // namespace panmap
