#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/render/overview.h"
#include "test_meshes.h"

namespace panmap {
namespace {

// A 4 x 4 m room: floor (instance 1), a box on it (2) and a ceiling (3) 2.5 m up.
LabelledMesh room() {
  LabelledMesh mesh;
  test::addQuad(&mesh, {0, 0, 0}, {4, 0, 0}, {4, 4, 0}, {0, 4, 0}, 1, 2, 8, Rgb8{0, 200, 0});
  test::addBox(&mesh, {1.5f, 1.5f, 0.0f}, {2.5f, 2.5f, 1.0f}, 2, 5, 4);
  test::addQuad(&mesh, {0, 0, 2.5f}, {4, 0, 2.5f}, {4, 4, 2.5f}, {0, 4, 2.5f}, 3, 22, 8,
                Rgb8{200, 0, 0});
  return mesh;
}

Rgb8 byInstance(const LabelledMesh& mesh, size_t v) {
  switch (mesh.instance[v]) {
    case 1:
      return Rgb8{0, 0, 250};
    case 2:
      return Rgb8{250, 250, 0};
    default:
      return Rgb8{250, 0, 250};
  }
}

// Counts pixels whose colour is a shade of `base` (each channel base * s for one s).
int shadesOf(const ColorImage& image, Rgb8 base) {
  int n = 0;
  for (size_t i = 0; i < image.size(); ++i) {
    const Rgb8 c = image.data()[i];
    if (c.r == 255 && c.g == 255 && c.b == 255) continue;
    const bool zero_r = base.r == 0, zero_g = base.g == 0, zero_b = base.b == 0;
    if ((c.r == 0) == zero_r && (c.g == 0) == zero_g && (c.b == 0) == zero_b) ++n;
  }
  return n;
}

TEST(Overview, EachColouringIsTheSameViewInItsColours) {
  const LabelledMesh mesh = room();
  const std::vector<ColorImage> pictures = renderOverviews(
      mesh, {vertexColours(mesh), [&](size_t v) { return byInstance(mesh, v); }}, 320, 240);
  ASSERT_EQ(pictures.size(), 2u);
  // A colouring's picture does not depend on the others drawn with it.
  const ColorImage own = renderOverviews(mesh, {vertexColours(mesh)}, 320, 240).front();
  int background = 0;
  for (size_t i = 0; i < own.size(); ++i) {
    ASSERT_EQ(pictures[0].data()[i].r, own.data()[i].r);
    ASSERT_EQ(pictures[0].data()[i].g, own.data()[i].g);
    ASSERT_EQ(pictures[0].data()[i].b, own.data()[i].b);
    // Both pictures have the same background: one rasterisation.
    const Rgb8 a = pictures[0].data()[i], b = pictures[1].data()[i];
    const bool a_white = a.r == 255 && a.g == 255 && a.b == 255;
    const bool b_white = b.r == 255 && b.g == 255 && b.b == 255;
    ASSERT_EQ(a_white, b_white);
    background += a_white;
  }
  EXPECT_GT(background, 1000);
  // The top 20 cm (the ceiling) is cut away: the floor and the box show, the ceiling not.
  EXPECT_GT(shadesOf(pictures[1], Rgb8{0, 0, 250}), 5000);
  EXPECT_GT(shadesOf(pictures[1], Rgb8{250, 250, 0}), 500);
  EXPECT_EQ(shadesOf(pictures[1], Rgb8{250, 0, 250}), 0);
  EXPECT_GT(shadesOf(pictures[0], Rgb8{0, 200, 0}), 5000);
  EXPECT_EQ(shadesOf(pictures[0], Rgb8{200, 0, 0}), 0);
}

TEST(Overview, AnEmptyMeshGivesOnePictureAColouring) {
  const std::vector<ColorImage> pictures = renderOverviews(LabelledMesh(),
                                                           {[](size_t) {
                                                              return Rgb8{1, 2, 3};
                                                            },
                                                            nullptr},
                                                           32, 24);
  ASSERT_EQ(pictures.size(), 2u);
  EXPECT_EQ(pictures[1].width(), 32);
}

}  // namespace
}  // namespace panmap
