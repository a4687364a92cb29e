#include <algorithm>
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/render/renderer.h"

namespace panmap {
namespace {

// Two triangles spanning an axis-aligned square in the plane x = const (normal -x), labelled.
void addQuad(LabelledMesh* mesh, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
             const Eigen::Vector3f& c, const Eigen::Vector3f& d, int32_t instance,
             int32_t semantic) {
  const int base = static_cast<int>(mesh->vertices.size());
  for (const auto& p : {a, b, c, d}) {
    mesh->vertices.push_back(p);
    mesh->instance.push_back(instance);
    mesh->semantic.push_back(semantic);
    mesh->colors.push_back(Rgb8{200, 100, 50});
  }
  mesh->faces.emplace_back(base, base + 1, base + 2);
  mesh->faces.emplace_back(base, base + 2, base + 3);
}

// Closed axis-aligned box, all six faces.
void addBox(LabelledMesh* mesh, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
            int32_t instance, int32_t semantic) {
  auto P = [&](int i, int j, int k) {
    return Eigen::Vector3f(i ? hi.x() : lo.x(), j ? hi.y() : lo.y(), k ? hi.z() : lo.z());
  };
  addQuad(mesh, P(0, 0, 0), P(0, 1, 0), P(0, 1, 1), P(0, 0, 1), instance, semantic);
  addQuad(mesh, P(1, 0, 0), P(1, 1, 0), P(1, 1, 1), P(1, 0, 1), instance, semantic);
  addQuad(mesh, P(0, 0, 0), P(1, 0, 0), P(1, 0, 1), P(0, 0, 1), instance, semantic);
  addQuad(mesh, P(0, 1, 0), P(1, 1, 0), P(1, 1, 1), P(0, 1, 1), instance, semantic);
  addQuad(mesh, P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), instance, semantic);
  addQuad(mesh, P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1), instance, semantic);
}

const PinholeCamera kCamera{525.0, 525.0, 319.5, 239.5, 640, 480};

// Camera at `eye` looking along `forward` (optical frame: z forward, y down, world z up).
Eigen::Isometry3d lookAlong(const Eigen::Vector3d& eye, const Eigen::Vector3d& forward) {
  const Eigen::Vector3d z = forward.normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

TEST(Renderer, TiltedPlaneMatchesAnalyticDepth) {
  LabelledMesh mesh;
  // A big wall x = 3 seen obliquely.
  addQuad(&mesh, {3, -20, -20}, {3, 20, -20}, {3, 20, 20}, {3, -20, 20}, 7, 1);
  const MeshRenderer renderer(mesh);
  const Eigen::Isometry3d T_W_C = lookAlong({0.2, 0.4, 1.1}, {1.0, 0.5, -0.3});
  const RenderedView view = renderer.render(kCamera, T_W_C);
  double max_error = 0.0;
  int covered = 0;
  for (int v = 0; v < 480; v += 7) {
    for (int u = 0; u < 640; u += 7) {
      const Eigen::Vector3d ray_W = T_W_C.linear() * kCamera.backProject(u, v, 1.0);
      const double t = (3.0 - T_W_C.translation().x()) / ray_W.x();  // z along the optical axis
      ASSERT_GT(t, 0.0);
      ASSERT_GT(view.depth_m(u, v), 0.0f) << u << " " << v;
      max_error = std::max(max_error, std::abs(view.depth_m(u, v) - t));
      EXPECT_EQ(view.instance(u, v), 7);
      EXPECT_EQ(view.semantic(u, v), 1);
      const double cos_i = std::abs(ray_W.normalized().x());
      EXPECT_NEAR(view.cos_incidence(u, v), cos_i, 1e-4);
      ++covered;
    }
  }
  EXPECT_LT(max_error, 1e-3);  // 1 mm
  EXPECT_GT(covered, 6000);
}

TEST(Renderer, BoxDepthAndLabelsMatchRayCasting) {
  LabelledMesh mesh;
  addBox(&mesh, {1.0f, -0.5f, 0.0f}, {1.8f, 0.4f, 0.9f}, 3, 5);  // a chair-sized box
  addBox(&mesh, {2.5f, 0.2f, 0.0f}, {3.0f, 1.0f, 2.0f}, 4, 3);   // behind and to the side
  const MeshRenderer renderer(mesh);
  const Eigen::Isometry3d T_W_C = lookAlong({-0.5, -0.3, 1.4}, {1.0, 0.15, -0.35});
  const RenderedView view = renderer.render(kCamera, T_W_C);
  const Eigen::AlignedBox3d boxes[2] = {
      {Eigen::Vector3d(1.0, -0.5, 0.0), Eigen::Vector3d(1.8, 0.4, 0.9)},
      {Eigen::Vector3d(2.5, 0.2, 0.0), Eigen::Vector3d(3.0, 1.0, 2.0)}};
  int hits[3] = {0, 0, 0};
  for (int v = 0; v < 480; v += 3) {
    for (int u = 0; u < 640; u += 3) {
      const Eigen::Vector3d dir = T_W_C.linear() * kCamera.backProject(u, v, 1.0);
      const Eigen::Vector3d o = T_W_C.translation();
      // Slab test along the ray parameterised by optical-axis depth.
      double best = 1e9;
      int best_box = -1;
      for (int b = 0; b < 2; ++b) {
        double t0 = 0.0, t1 = 1e9;
        for (int k = 0; k < 3; ++k) {
          const double a = (boxes[b].min()[k] - o[k]) / dir[k];
          const double c = (boxes[b].max()[k] - o[k]) / dir[k];
          t0 = std::max(t0, std::min(a, c));
          t1 = std::min(t1, std::max(a, c));
        }
        if (t0 <= t1 && t0 < best) {
          best = t0;
          best_box = b;
        }
      }
      // Skip pixels within a pixel of an outline, where sampling may go either way.
      bool near_edge = false;
      for (int k = 0; k < 3 && best_box >= 0; ++k) {
        const double x = o[k] + best * dir[k];
        const double lo = boxes[best_box].min()[k], hi = boxes[best_box].max()[k];
        near_edge |= std::min(std::abs(x - lo), std::abs(x - hi)) < 0.004 * best &&
                     std::min(std::abs(x - lo), std::abs(x - hi)) > 1e-9;
      }
      const int expected_instance = best_box < 0 ? 0 : best_box + 3;
      if (view.instance(u, v) != expected_instance) {
        // Only outline pixels may disagree.
        int disagree_far_from_edge = 0;
        for (int k = 0; k < 3 && best_box >= 0; ++k) {
          const double x = o[k] + best * dir[k];
          const double lo = boxes[best_box].min()[k], hi = boxes[best_box].max()[k];
          disagree_far_from_edge += std::min(std::abs(x - lo), std::abs(x - hi)) < 0.01 * best;
        }
        EXPECT_TRUE(best_box < 0 || disagree_far_from_edge >= 2) << u << " " << v;
        continue;
      }
      ++hits[expected_instance == 0 ? 0 : expected_instance - 2];
      if (best_box >= 0) {
        EXPECT_NEAR(view.depth_m(u, v), best, 1e-3) << u << " " << v;
        EXPECT_EQ(view.semantic(u, v), best_box == 0 ? 5 : 3);
      } else {
        EXPECT_EQ(view.depth_m(u, v), 0.0f);
      }
      (void)near_edge;
    }
  }
  EXPECT_GT(hits[0], 1000);  // background
  EXPECT_GT(hits[1], 1000);  // box 3
  EXPECT_GT(hits[2], 200);   // box 4
}

TEST(Renderer, NearPlaneClipsSurfacesAroundTheCamera) {
  LabelledMesh mesh;
  // Floor under the camera extends behind it: triangles cross the camera plane.
  addQuad(&mesh, {-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}, 2, 2);
  const MeshRenderer renderer(mesh);
  const Eigen::Isometry3d T_W_C = lookAlong({0, 0, 1.5}, {1.0, 0.0, -0.2});
  const RenderedView view = renderer.render(kCamera, T_W_C);
  // Bottom rows see the floor; depth follows the analytic plane z = 0.
  for (int u = 0; u < 640; u += 50) {
    const int v = 470;
    const Eigen::Vector3d ray_W = T_W_C.linear() * kCamera.backProject(u, v, 1.0);
    const double t = -1.5 / ray_W.z();
    EXPECT_NEAR(view.depth_m(u, v), t, 1e-3);
  }
  EXPECT_EQ(view.instance(320, 10), 0);  // sky above the horizon
}

TEST(Renderer, CullingLeavesTheImageBitIdentical) {
  // A floor of 1 m tiles and a 20 x 20 grid of boxes: many face runs, some behind the camera,
  // some beside the image, some crossing the near plane around the camera.
  LabelledMesh mesh;
  for (int i = -10; i < 10; ++i) {
    for (int j = -10; j < 10; ++j) {
      addQuad(&mesh, Eigen::Vector3f(i, j, 0), Eigen::Vector3f(i + 1, j, 0),
              Eigen::Vector3f(i + 1, j + 1, 0), Eigen::Vector3f(i, j + 1, 0), 1, 2);
      addBox(&mesh, Eigen::Vector3f(i + 0.3f, j + 0.3f, 0.0f),
             Eigen::Vector3f(i + 0.6f, j + 0.7f, 0.4f + 0.05f * ((i * 7 + j * 3) & 15)),
             100 + (i + 10) * 20 + (j + 10), 5);
    }
  }
  RenderConfig off;
  off.cull = false;
  const MeshRenderer culled(mesh), full(mesh, off);
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> views = {
      {{0.05, 0.1, 1.5}, {1.0, 0.2, -0.3}},  {{-9.0, -9.0, 1.2}, {1.0, 1.0, -0.2}},
      {{3.5, -2.0, 0.3}, {-0.3, 1.0, 0.0}},  {{0.45, 0.5, 0.2}, {0.0, 1.0, 0.1}},
      {{5.0, 5.0, 6.0}, {-0.2, -0.1, -1.0}}, {{12.0, 0.0, 1.0}, {-1.0, 0.0, 0.0}},
      {{0.0, 0.0, 1.0}, {1.0, 0.0, 0.0}}};
  for (const auto& [eye, forward] : views) {
    const Eigen::Isometry3d T_W_C = lookAlong(eye, forward);
    const RenderedView a = culled.render(kCamera, T_W_C), b = full.render(kCamera, T_W_C);
    int drawn = 0;
    for (int v = 0; v < kCamera.height; ++v) {
      for (int u = 0; u < kCamera.width; ++u) {
        ASSERT_EQ(a.depth_m(u, v), b.depth_m(u, v)) << "pixel " << u << "," << v;
        ASSERT_EQ(a.instance(u, v), b.instance(u, v)) << "pixel " << u << "," << v;
        drawn += b.instance(u, v) > 0 ? 1 : 0;
      }
    }
    EXPECT_GT(drawn, 10000) << "the view must see part of the scene";
  }
}

// renderFaces() reports what render() shades: the same pixels, the same incidence, and the
// colour of each pixel's face (its first vertex) shaded by it.
TEST(Renderer, RenderFacesGivesTheFacesAndAnglesThatRenderShades) {
  LabelledMesh mesh;
  addBox(&mesh, {2.0f, -0.5f, -0.5f}, {3.0f, 0.5f, 0.5f}, 4, 5);
  addQuad(&mesh, {4, -3, -2}, {4, 3, -2}, {4, 3, 2}, {4, -3, 2}, 6, 1);
  for (size_t v = 0; v < mesh.colors.size(); ++v) {
    mesh.colors[v] = Rgb8{static_cast<uint8_t>(v * 37), static_cast<uint8_t>(v * 11), 90};
  }
  RenderConfig config;
  config.texture_contrast = 0.0f;
  const MeshRenderer renderer(mesh, config);
  const Eigen::Isometry3d T_W_C = lookAlong({0.0, 0.7, 0.4}, {1.0, -0.2, -0.1});
  const RenderedView view = renderer.render(kCamera, T_W_C);
  Image<int32_t> face;
  Image<float> cos_incidence;
  renderer.renderFaces(kCamera, T_W_C, &face, &cos_incidence);
  int box = 0, wall = 0;
  for (int v = 0; v < kCamera.height; ++v) {
    for (int u = 0; u < kCamera.width; ++u) {
      const int32_t f = face(u, v);
      ASSERT_EQ(f >= 0, view.depth_m(u, v) > 0.0f) << u << "," << v;
      if (f < 0) continue;
      ASSERT_LT(f, static_cast<int32_t>(mesh.faces.size()));
      const int32_t first = mesh.faces[f][0];
      EXPECT_EQ(mesh.instance[first], view.instance(u, v));
      ASSERT_EQ(cos_incidence(u, v), view.cos_incidence(u, v)) << u << "," << v;
      const float shade = config.ambient + (1.0f - config.ambient) * cos_incidence(u, v);
      const Rgb8 base = mesh.colors[first], got = view.color(u, v);
      EXPECT_EQ(got.r, static_cast<uint8_t>(std::min(255.0f, base.r * shade + 0.5f)));
      EXPECT_EQ(got.g, static_cast<uint8_t>(std::min(255.0f, base.g * shade + 0.5f)));
      EXPECT_EQ(got.b, static_cast<uint8_t>(std::min(255.0f, base.b * shade + 0.5f)));
      (view.instance(u, v) == 4 ? box : wall) += 1;
    }
  }
  EXPECT_GT(box, 1000);
  EXPECT_GT(wall, 1000);
}

// A mesh without labels or colours renders grey with no labels (the renderer then keeps no
// per-face arrays for them); taking the mesh over gives the same image as copying it.
TEST(Renderer, AMeshWithoutLabelsOrColoursRendersGreyAndUnlabelled) {
  LabelledMesh mesh;
  addQuad(&mesh, {3, -1, -1}, {3, 1, -1}, {3, 1, 1}, {3, -1, 1}, 1, 1);
  mesh.instance.clear();
  mesh.semantic.clear();
  mesh.colors.clear();
  RenderConfig config;
  config.texture_contrast = 0.0f;
  config.ambient = 1.0f;
  const MeshRenderer copied(mesh, config);
  const MeshRenderer moved(LabelledMesh(mesh), config);
  const Eigen::Isometry3d T_W_C = lookAlong({0.0, 0.0, 0.0}, {1.0, 0.0, 0.0});
  const RenderedView a = copied.render(kCamera, T_W_C), b = moved.render(kCamera, T_W_C);
  ASSERT_GT(a.depth_m(320, 240), 0.0f);
  EXPECT_EQ(a.color(320, 240).r, 180);
  EXPECT_EQ(a.color(320, 240).b, 180);
  EXPECT_EQ(a.instance(320, 240), 0);
  EXPECT_EQ(a.semantic(320, 240), 0);
  for (size_t i = 0; i < a.color.size(); ++i) {
    ASSERT_EQ(a.depth_m.data()[i], b.depth_m.data()[i]);
    ASSERT_EQ(a.color.data()[i].g, b.color.data()[i].g);
  }
}

// The overview's options: a shared mesh, faces above a height left out, normals computed per
// pixel instead of kept; the image otherwise the same bits.
TEST(Renderer, SharedMeshHeightCutAndPerPixelNormalsGiveTheSameImage) {
  LabelledMesh mesh;
  addQuad(&mesh, {4, -3, -2}, {4, 3, -2}, {4, 3, 4}, {4, -3, 4}, 1, 1);            // a wall x = 4
  addQuad(&mesh, {3, -1, 1.5f}, {3, 1, 1.5f}, {3, 1, 1.8f}, {3, -1, 1.8f}, 2, 2);  // high panel
  addBox(&mesh, {2.0f, -0.5f, -0.5f}, {2.5f, 0.5f, 0.5f}, 3, 3);
  const auto shared = std::make_shared<const LabelledMesh>(mesh);
  RenderConfig lean;
  lean.keep_face_data = false;
  const MeshRenderer kept(mesh), computed(shared, lean);
  EXPECT_EQ(&computed.mesh(), shared.get());
  const Eigen::Isometry3d T_W_C = lookAlong({0.0, 0.3, 0.5}, {1.0, -0.1, 0.1});
  const RenderedView a = kept.render(kCamera, T_W_C), b = computed.render(kCamera, T_W_C);
  int panel = 0;
  for (size_t i = 0; i < a.depth_m.size(); ++i) {
    ASSERT_EQ(a.depth_m.data()[i], b.depth_m.data()[i]);
    ASSERT_EQ(a.cos_incidence.data()[i], b.cos_incidence.data()[i]);
    ASSERT_EQ(a.color.data()[i].r, b.color.data()[i].r);
    ASSERT_EQ(a.instance.data()[i], b.instance.data()[i]);
    panel += a.instance.data()[i] == 2;
  }
  ASSERT_GT(panel, 500);
  // Cut above 1.4 m: the panel (1.5-1.8 m) goes, the wall behind it shows there instead; the
  // wall's faces reach above the cut but have corners below it, so they stay.
  RenderConfig cut;
  cut.max_face_height_m = 1.4f;
  const RenderedView c = MeshRenderer(shared, cut).render(kCamera, T_W_C);
  int wall_where_panel = 0;
  for (size_t i = 0; i < a.depth_m.size(); ++i) {
    ASSERT_NE(c.instance.data()[i], 2);
    if (a.instance.data()[i] == 2) wall_where_panel += c.instance.data()[i] == 1;
    if (a.instance.data()[i] != 2) {
      ASSERT_EQ(c.depth_m.data()[i], a.depth_m.data()[i]);
    }
  }
  EXPECT_EQ(wall_where_panel, panel);
  RenderConfig bad;
  bad.max_face_height_m = std::nanf("");
  EXPECT_THROW(MeshRenderer(shared, bad), Error);
  EXPECT_THROW(MeshRenderer(std::shared_ptr<const LabelledMesh>(), RenderConfig()), Error);
}

TEST(Renderer, ShadedColourRoundsAndSaturates) {
  const Rgb8 bright = shadedColour(Rgb8{200, 100, 0}, 1.5f);
  EXPECT_EQ(bright.r, 255);
  EXPECT_EQ(bright.g, 150);
  EXPECT_EQ(bright.b, 0);
  const Rgb8 dim = shadedColour(Rgb8{10, 11, 12}, 0.25f);  // 2.5, 2.75, 3.0 round to 3, 3, 3
  EXPECT_EQ(dim.r, 3);
  EXPECT_EQ(dim.g, 3);
  EXPECT_EQ(dim.b, 3);
  const Rgb8 half = shadedColour(Rgb8{1, 3, 255}, 0.5f);  // 0.5, 1.5, 127.5 round half up
  EXPECT_EQ(half.r, 1);
  EXPECT_EQ(half.g, 2);
  EXPECT_EQ(half.b, 128);
}

TEST(Renderer, RejectsBadInput) {
  LabelledMesh bad;
  bad.vertices = {{0, 0, 0}};
  bad.faces = {{0, 1, 2}};
  EXPECT_THROW(MeshRenderer{bad}, Error);
  LabelledMesh mesh;
  addQuad(&mesh, {3, -1, -1}, {3, 1, -1}, {3, 1, 1}, {3, -1, 1}, 1, 1);
  const MeshRenderer renderer(mesh);
  EXPECT_THROW(renderer.render(PinholeCamera{0, 0, 0, 0, 640, 480}, Eigen::Isometry3d::Identity()),
               Error);
}

}  // namespace
}  // namespace panmap
