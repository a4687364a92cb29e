// Geometric segmentation and panoptic-geometric fusion (paper III-A) on depth images rendered
// analytically from planes, and a sanity check on a real 7-Scenes frame.
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "panmap/core/error.h"
#include "panmap/segmentation/internal/depth_edges.h"
#include "panmap/segmentation/panoptic_geometric.h"
#include "test_helpers.h"

namespace panmap {
namespace {

constexpr double kDepthScaleM = 0.0001;  // 0.1 mm units: quantisation far below the tolerances
constexpr double kFocalPx = 525.0;

PinholeCamera testCamera() { return PinholeCamera{kFocalPx, kFocalPx, 319.5, 239.5, 640, 480}; }

// Distance along the optical axis to the scene through a pixel's ray (x, y, 1), or <= 0 where
// the ray hits nothing.
using SceneFn = std::function<double(double ray_x, double ray_y)>;

RgbdFrame render(const SceneFn& scene) {
  RgbdFrame frame;
  frame.camera = testCamera();
  frame.depth_scale_m = kDepthScaleM;
  frame.depth = DepthImage(frame.camera.width, frame.camera.height);
  for (int v = 0; v < frame.camera.height; ++v) {
    for (int u = 0; u < frame.camera.width; ++u) {
      const double z_m =
          scene((u - frame.camera.cx) / frame.camera.fx, (v - frame.camera.cy) / frame.camera.fy);
      frame.depth(u, v) = z_m > 0.0 ? static_cast<uint16_t>(std::lround(z_m / kDepthScaleM)) : 0;
    }
  }
  return frame;
}

// Depth along the ray (x, y, 1) to the plane n . p = offset_m, or 0 when it is parallel or
// behind the camera.
double planeDepth(const Eigen::Vector3d& n, double offset_m, double ray_x, double ray_y) {
  const double denominator = n.dot(Eigen::Vector3d(ray_x, ray_y, 1.0));
  if (std::abs(denominator) < 1e-12) return 0.0;
  const double z = offset_m / denominator;
  return z > 0.0 ? z : 0.0;
}

// A fronto-parallel wall at 3 m with a floor 1 m below the camera: the concave crease is the
// image row where the ray's y is 1 / 3. (The floor is no steeper than 1.7 cm a pixel there,
// under the 3 cm a 1% depth jump needs.)
double floorAndWall(double ray_x, double ray_y) {
  (void)ray_x;
  const double wall_m = 3.0;
  const double floor_m = ray_y > 0.0 ? 1.0 / ray_y : 1e9;
  return std::min(wall_m, floor_m);
}
constexpr double kCreaseRow = 239.5 + kFocalPx * 1.0 / 3.0;

// A wall at 3 m with a square box face at 2 m, |x|, |y| <= 0.3 m.
double boxBeforeWall(double ray_x, double ray_y) {
  if (std::abs(ray_x * 2.0) <= 0.3 && std::abs(ray_y * 2.0) <= 0.3) return 2.0;
  return 3.0;
}

struct SegmentStats {
  std::map<int32_t, int> area_px;  ///< per non-zero id
};

SegmentStats stats(const LabelImage& labels) {
  SegmentStats s;
  for (int32_t id : labels.pixels()) {
    if (id != 0) ++s.area_px[id];
  }
  return s;
}

// Ids are 1..N with no gap.
void expectConsecutiveIds(const SegmentStats& s) {
  int expected = 1;
  for (const auto& [id, area] : s.area_px) EXPECT_EQ(id, expected++);
}

TEST(DepthSegmentation, TiltedPlaneNormalsMatchAnalyticNormal) {
  // Plane through (0, 0, 2) whose normal toward the camera is n.
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.4, -1.0).normalized();
  const double offset_m = n.dot(Eigen::Vector3d(0.0, 0.0, 2.0));
  const RgbdFrame frame = render([&](double x, double y) { return planeDepth(n, offset_m, x, y); });
  PanopticGeometricSegmenter segmenter({}, {});
  const FrameSegmentation result = segmenter.segment(frame, nullptr);

  const int border_px = 13;
  double worst_deg = 0.0;
  for (int v = border_px; v < 480 - border_px; v += 3) {
    for (int u = border_px; u < 640 - border_px; u += 3) {
      const Eigen::Vector3d estimate = segmenter.normal(u, v).cast<double>();
      ASSERT_NEAR(estimate.norm(), 1.0, 1e-5) << "at " << u << ", " << v;
      worst_deg = std::max(worst_deg, std::acos(std::min(1.0, estimate.dot(n))) * 180.0 / M_PI);
    }
  }
  EXPECT_LT(worst_deg, 2.0);
  // Normals exist up to the border, still toward the camera.
  EXPECT_GT(-segmenter.normal(0, 0).cast<double>().dot(Eigen::Vector3d(0.0, 0.0, 1.0)), 0.5);

  // One plane, one segment covering it.
  const SegmentStats s = stats(result.geometric);
  ASSERT_EQ(s.area_px.size(), 1u);
  EXPECT_GT(s.area_px.begin()->second, 0.95 * 640 * 480);
}

TEST(DepthSegmentation, PairConvexityFlagsOnlyConcaveBends) {
  // Faces at +-45 degrees, normals toward the camera (-z), points 1 cm apart across the crease.
  const float s = std::sqrt(0.5f);
  // Ridge z = 2 + |x| (convex toward the camera): n_left = (-s, 0, -s), n_right = (s, 0, -s).
  EXPECT_EQ(internal::pairConvexity(0.01f, 0.0f, 0.0f, -s, 0.0f, -s, s, 0.0f, -s), 1.0f);
  // Valley z = 2 - |x| (concave): n_left = (s, 0, -s), n_right = (-s, 0, -s); n_i . n_j = 0.
  EXPECT_NEAR(internal::pairConvexity(0.01f, 0.0f, 0.0f, s, 0.0f, -s, -s, 0.0f, -s), 0.0f, 1e-6);
  // Symmetric in i and j: swapping them negates p_j - p_i and swaps the normals.
  EXPECT_NEAR(internal::pairConvexity(-0.01f, 0.0f, 0.0f, -s, 0.0f, -s, s, 0.0f, -s), 0.0f, 1e-6);
  // A plane is flat: 1 whatever the offset.
  EXPECT_EQ(internal::pairConvexity(0.01f, 0.02f, 0.03f, 0.0f, 0.0f, -1.0f, 0.0f, 0.0f, -1.0f),
            1.0f);
  // Blended normals on the same face of a convex ridge (both tilted toward the ridge, the one
  // nearer it more): convex, where the one-sided test (p_j - p_i) . n_i > 0 would say concave.
  const float a = 0.3f, b = 0.1f;  // x components of n_i (farther) and n_j (nearer the ridge)
  const float ni_z = -std::sqrt(1.0f - a * a), nj_z = -std::sqrt(1.0f - b * b);
  EXPECT_EQ(internal::pairConvexity(0.01f, 0.0f, -0.01f, -a, 0.0f, ni_z, -b, 0.0f, nj_z), 1.0f);
}

TEST(DepthSegmentation, ConcaveCreaseSplitsFloorFromWall) {
  PanopticGeometricSegmenter segmenter({}, {});
  const FrameSegmentation result = segmenter.segment(render(floorAndWall), nullptr);
  const SegmentStats s = stats(result.geometric);
  ASSERT_EQ(s.area_px.size(), 2u);
  const int32_t wall = result.geometric(320, 100);
  const int32_t floor = result.geometric(320, 460);
  EXPECT_EQ(wall, 1);  // raster order: the wall starts first
  EXPECT_EQ(floor, 2);
  // Each segment stays on its side of the crease, which is a concave edge and no jump.
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const int32_t id = result.geometric(u, v);
      if (id == wall) {
        ASSERT_LT(v, kCreaseRow) << u << ", " << v;
      } else if (id == floor) {
        ASSERT_GT(v, kCreaseRow) << u << ", " << v;
      }
    }
  }
  // Along the crease (row 414.5) the edge is concave, not a jump.
  for (int u = 20; u < 620; u += 50) {
    for (const int v : {414, 415}) {
      EXPECT_TRUE(segmenter.edgeFlags()(u, v) & kEdgeConcave) << u << ", " << v;
      EXPECT_FALSE(segmenter.edgeFlags()(u, v) & kEdgeDiscontinuity) << u << ", " << v;
    }
  }
  // Far from the crease the surfaces are flat: convexity 1.
  EXPECT_FLOAT_EQ(segmenter.minConvexity()(320, 100), 1.0f);
}

TEST(DepthSegmentation, ConvexRidgeDoesNotSplit) {
  // A box edge seen from outside: two faces at 45 degrees to the optical axis meeting in a
  // vertical ridge 2 m ahead, z = 2 + |x|. Only concave edges and jumps split, so one segment.
  const RgbdFrame frame = render([](double x, double) { return 2.0 / (1.0 - std::abs(x)); });
  PanopticGeometricSegmenter segmenter({}, {});
  const FrameSegmentation result = segmenter.segment(frame, nullptr);
  const SegmentStats s = stats(result.geometric);
  ASSERT_EQ(s.area_px.size(), 1u);
  EXPECT_GT(s.area_px.begin()->second, 0.95 * 640 * 480);
  for (int v = 20; v < 460; v += 40) EXPECT_EQ(result.geometric(320, v), 1) << v;

  // The mirrored valley, z = 2 - |x| seen from inside, does split along x = 0.
  const RgbdFrame valley = render([](double x, double) { return 2.0 / (1.0 + std::abs(x)); });
  const FrameSegmentation split = segmenter.segment(valley, nullptr);
  ASSERT_EQ(stats(split.geometric).area_px.size(), 2u);
  EXPECT_EQ(split.geometric(100, 240), 1);
  EXPECT_EQ(split.geometric(540, 240), 2);
  EXPECT_EQ(split.geometric(320, 240), 0);
}

TEST(DepthSegmentation, DepthStepSplitsBoxFromWall) {
  PanopticGeometricSegmenter segmenter({}, {});
  const FrameSegmentation result = segmenter.segment(render(boxBeforeWall), nullptr);
  const SegmentStats s = stats(result.geometric);
  ASSERT_EQ(s.area_px.size(), 2u);
  const int32_t wall = result.geometric(20, 20);
  const int32_t box = result.geometric(320, 240);
  EXPECT_EQ(wall, 1);
  EXPECT_EQ(box, 2);
  // Exactly two: the wall beside the box keeps its own normal (the quadrants holding the box
  // are left out), so no ring of tilted normals is cut off by a concave band.
  for (const int u : {396, 401, 404, 410}) {
    EXPECT_NEAR(segmenter.normal(u, 240).z(), -1.0f, 1e-4) << u;
  }
  // The box face spans |u - 319.5| <= 0.15 * 525 = 78.75 px; both sides of its border jump.
  EXPECT_TRUE(segmenter.edgeFlags()(398, 240) & kEdgeDiscontinuity);
  EXPECT_TRUE(segmenter.edgeFlags()(399, 240) & kEdgeDiscontinuity);
  EXPECT_FALSE(segmenter.edgeFlags()(396, 240) & kEdgeDiscontinuity);
  EXPECT_FALSE(segmenter.edgeFlags()(401, 240) & kEdgeDiscontinuity);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      if (result.geometric(u, v) == box) {
        ASSERT_LE(std::abs(u - 319.5), 78.75) << u << ", " << v;
        ASSERT_LE(std::abs(v - 239.5), 78.75) << u << ", " << v;
      }
    }
  }
}

TEST(DepthSegmentation, SmallSegmentsAreDropped) {
  // A 6 x 6 px patch 1 m in front of the wall is cut out by jumps and too small to keep.
  const RgbdFrame frame = render([](double x, double y) {
    return std::abs(x) < 3.0 / kFocalPx && std::abs(y) < 3.0 / kFocalPx ? 2.0 : 3.0;
  });
  PanopticGeometricSegmenter segmenter({}, {});
  const FrameSegmentation result = segmenter.segment(frame, nullptr);
  EXPECT_EQ(result.geometric(320, 240), 0);
  EXPECT_EQ(stats(result.geometric).area_px.size(), 1u);

  // A minimum above the box face's area drops the box but keeps the wall.
  DepthSegmentationConfig config;
  config.min_segment_px = 30000;  // the face is ~157 x 157 = 24,600 px
  PanopticGeometricSegmenter strict(config, {});
  const FrameSegmentation kept = strict.segment(render(boxBeforeWall), nullptr);
  const SegmentStats s = stats(kept.geometric);
  ASSERT_EQ(s.area_px.size(), 1u);
  EXPECT_EQ(kept.geometric(320, 240), 0);
  EXPECT_EQ(kept.geometric(20, 20), 1);
  for (const auto& [id, area] : s.area_px) EXPECT_GE(area, config.min_segment_px);
}

TEST(DepthSegmentation, InvalidAndFarDepthIsNoSegment) {
  RgbdFrame frame = render([](double, double) { return 2.0; });
  for (int v = 200; v < 260; ++v) {
    for (int u = 100; u < 200; ++u) frame.depth(u, v) = 0;
    for (int u = 400; u < 500; ++u) frame.depth(u, v) = 60000;  // 6 m, beyond max_depth_m
  }
  DepthSegmentationConfig config;
  config.max_depth_m = 5.0f;
  PanopticGeometricSegmenter segmenter(config, {});
  const FrameSegmentation result = segmenter.segment(frame, nullptr);
  for (int v = 200; v < 260; ++v) {
    for (const int u : {100, 150, 199, 400, 450, 499}) {
      EXPECT_EQ(result.geometric(u, v), 0) << u << ", " << v;
      EXPECT_TRUE(segmenter.edgeFlags()(u, v) & kEdgeInvalidDepth) << u << ", " << v;
      EXPECT_EQ(segmenter.normal(u, v), Eigen::Vector3f::Zero());
    }
  }
  // Valid pixels next to a hole jump to it (released-code behaviour); farther ones do not.
  EXPECT_TRUE(segmenter.edgeFlags()(99, 230) & kEdgeDiscontinuity);
  EXPECT_EQ(segmenter.edgeFlags()(90, 230), 0);
  EXPECT_EQ(stats(result.geometric).area_px.size(), 1u);
}

TEST(DepthSegmentation, ConfigChecksNameTheField) {
  DepthSegmentationConfig even;
  even.normals_window_px = 12;
  try {
    even.check();
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("normals_window_px"), std::string::npos) << e.what();
  }
  DepthSegmentationConfig threads;
  threads.num_threads = 0;
  EXPECT_THROW(PanopticGeometricSegmenter(threads, {}), Error);
  SurfaceFusionConfig stuff;
  stuff.stuff_confidence = 1.5f;
  EXPECT_THROW(PanopticGeometricSegmenter({}, stuff), Error);
}

// A fronto-parallel wall (one geometric segment) under three vertical mask bands.
struct BandedWall {
  RgbdFrame frame = render([](double, double) { return 2.0; });
  PanopticFrame panoptic;
  BandedWall() {
    panoptic.segment_ids = LabelImage(640, 480);
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        // A chair (thing 7), the wall (stuff 3), then no mask but for an unknown class (9).
        const int32_t id = u < 200 ? 7 : u < 400 ? 3 : v < 100 ? 9 : 0;
        panoptic.segment_ids(u, v) = id;
      }
    }
    panoptic.segments = {{3, 1, 101, false, 0.9f}, {7, 5, 62, true, 0.8f}, {9, 0, 200, true, 0.7f}};
  }
};

TEST(SurfaceFusion, MasksSplitOneSegmentIntoSurfaces) {
  BandedWall scene;
  PanopticGeometricSegmenter segmenter({}, {});
  const FrameSegmentation result = segmenter.segment(scene.frame, &scene.panoptic);
  ASSERT_EQ(stats(result.geometric).area_px.size(), 1u);
  ASSERT_EQ(result.surface_list.size(), 3u);

  // Order (geometric segment, panoptic id): background 0, stuff 3, thing 7.
  const Surface& background = result.surface_list[0];
  const Surface& stuff = result.surface_list[1];
  const Surface& thing = result.surface_list[2];
  for (size_t k = 0; k < 3; ++k) EXPECT_EQ(result.surface_list[k].id, static_cast<int32_t>(k + 1));
  EXPECT_EQ(background.panoptic_segment, 0);
  EXPECT_EQ(background.category, 0);
  EXPECT_FALSE(background.is_thing);
  EXPECT_FLOAT_EQ(background.confidence, 0.5f);
  EXPECT_EQ(stuff.panoptic_segment, 3);
  EXPECT_EQ(stuff.category, 1);
  EXPECT_FALSE(stuff.is_thing);
  EXPECT_FLOAT_EQ(stuff.confidence, 0.5f);  // Eq. 1: stuff, not its 0.9 score
  EXPECT_EQ(thing.panoptic_segment, 7);
  EXPECT_EQ(thing.category, 5);
  EXPECT_TRUE(thing.is_thing);
  EXPECT_FLOAT_EQ(thing.confidence, 0.8f);  // Eq. 1: thing, its score
  for (const Surface& s : result.surface_list) EXPECT_EQ(s.geometric_segment, 1);

  // Pixels: surface ids follow the masks inside the segment, 0 outside it; counts match.
  std::map<int32_t, int> area;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const int32_t surface = result.surfaces(u, v);
      if (result.geometric(u, v) == 0) {
        ASSERT_EQ(surface, 0);
        continue;
      }
      ++area[surface];
      ASSERT_EQ(surface, u < 200 ? 3 : u < 400 ? 2 : 1) << u << ", " << v;
    }
  }
  for (const Surface& s : result.surface_list) EXPECT_EQ(area[s.id], s.num_pixels);
}

TEST(SurfaceFusion, SmallIntersectionsAreDropped) {
  BandedWall scene;
  // A 5 x 5 px thing inside the background band: 25 px < min_surface_px (50).
  for (int v = 300; v < 305; ++v) {
    for (int u = 500; u < 505; ++u) scene.panoptic.segment_ids(u, v) = 11;
  }
  scene.panoptic.segments.push_back({11, 5, 62, true, 0.9f});
  PanopticGeometricSegmenter segmenter({}, {});
  const FrameSegmentation result = segmenter.segment(scene.frame, &scene.panoptic);
  EXPECT_EQ(result.surface_list.size(), 3u);
  EXPECT_EQ(result.surfaces(502, 302), 0);
  EXPECT_EQ(result.surfaces(510, 302), 1);
}

// Two 12 x 12 px box faces side by side before a wall at 3 m (columns 300-311 at 1.0 m, 312-323
// at 1.5 m; rows 200-211), under one chair mask (thing 9). Too small for min_segment_px 400,
// they are no geometric segment, as a far chair is for the default window and minimum.
struct SmallThingsBeforeWall {
  RgbdFrame frame = render([](double x, double y) {
    auto column = [](double ray) { return std::lround(319.5 + kFocalPx * ray); };
    const long u = column(x), v = std::lround(239.5 + kFocalPx * y);
    if (v < 200 || v >= 212 || u < 300 || u >= 324) return 3.0;
    return u < 312 ? 1.0 : 1.5;
  });
  PanopticFrame panoptic;
  SmallThingsBeforeWall() {
    panoptic.segment_ids = LabelImage(640, 480);
    for (int v = 200; v < 212; ++v) {
      for (int u = 300; u < 324; ++u) panoptic.segment_ids(u, v) = 9;
    }
    panoptic.segments = {{9, 5, 62, true, 0.8f}};
  }
};

TEST(SurfaceFusion, AThingMaskWithoutSurfaceBecomesSurfacesSplitAtDepthSteps) {
  SmallThingsBeforeWall scene;
  DepthSegmentationConfig depth;
  depth.min_segment_px = 400;
  PanopticGeometricSegmenter segmenter(depth, {});
  const FrameSegmentation result = segmenter.segment(scene.frame, &scene.panoptic);
  for (int v = 200; v < 212; ++v) {
    for (int u = 300; u < 324; ++u) ASSERT_EQ(result.geometric(u, v), 0) << u << ", " << v;
  }
  // The wall's background surface first, then one surface per box face: the 50 cm step
  // between them splits the mask, and each face is 144 px >= min_surface_px.
  ASSERT_EQ(result.surface_list.size(), 3u);
  EXPECT_EQ(result.surface_list[0].panoptic_segment, 0);
  for (size_t k = 1; k < 3; ++k) {
    const Surface& s = result.surface_list[k];
    EXPECT_EQ(s.id, static_cast<int32_t>(k + 1));
    EXPECT_EQ(s.geometric_segment, 0);
    EXPECT_EQ(s.panoptic_segment, 9);
    EXPECT_EQ(s.category, 5);
    EXPECT_TRUE(s.is_thing);
    EXPECT_FLOAT_EQ(s.confidence, 0.8f);
    EXPECT_EQ(s.num_pixels, 144);
  }
  for (int v = 200; v < 212; ++v) {
    for (int u = 300; u < 324; ++u) ASSERT_EQ(result.surfaces(u, v), u < 312 ? 2 : 3);
  }
  EXPECT_EQ(result.surfaces(290, 205), 1);  // the wall beside them keeps its surface

  // Without mask-only surfaces the chair casts no vote.
  SurfaceFusionConfig off;
  off.mask_only_surfaces = false;
  PanopticGeometricSegmenter without(depth, off);
  const FrameSegmentation none = without.segment(scene.frame, &scene.panoptic);
  ASSERT_EQ(none.surface_list.size(), 1u);
  EXPECT_EQ(none.surfaces(305, 205), 0);
}

TEST(SurfaceFusion, MaskOnlySurfacesNeedAThingOfKnownClassWithoutSurfaceAndEnoughPixels) {
  SmallThingsBeforeWall scene;
  DepthSegmentationConfig depth;
  depth.min_segment_px = 400;
  auto surfacesWith = [&](const PanopticSegment& segment, int min_surface_px) {
    PanopticFrame panoptic = scene.panoptic;
    panoptic.segments = {segment};
    SurfaceFusionConfig fusion;
    fusion.min_surface_px = min_surface_px;
    return PanopticGeometricSegmenter(depth, fusion).segment(scene.frame, &panoptic);
  };
  // Stuff and an unknown class name no object to find.
  EXPECT_EQ(surfacesWith({9, 1, 101, false, 0.9f}, 50).surface_list.size(), 1u);
  EXPECT_EQ(surfacesWith({9, 0, 62, true, 0.8f}, 50).surface_list.size(), 1u);
  // Parts below min_surface_px are dropped as any surface is.
  EXPECT_EQ(surfacesWith({9, 5, 62, true, 0.8f}, 145).surface_list.size(), 1u);
  EXPECT_EQ(surfacesWith({9, 5, 62, true, 0.8f}, 144).surface_list.size(), 3u);

  // A mask that also covers 120 px of the wall has a surface there (the wall's pixels next to
  // the step are edges): its parts on the boxes stay without one, as before.
  PanopticFrame wider = scene.panoptic;
  for (int v = 200; v < 212; ++v) {
    for (int u = 290; u < 300; ++u) wider.segment_ids(u, v) = 9;
  }
  const FrameSegmentation result =
      PanopticGeometricSegmenter(depth, {}).segment(scene.frame, &wider);
  ASSERT_EQ(result.surface_list.size(), 2u);
  EXPECT_EQ(result.surface_list[1].geometric_segment, 1);
  EXPECT_EQ(result.surfaces(305, 205), 0);
}

TEST(SurfaceFusion, GeometryOnlyIgnoresMasks) {
  BandedWall scene;
  SurfaceFusionConfig fusion;
  fusion.geometry_only = true;
  PanopticGeometricSegmenter segmenter({}, fusion);
  const FrameSegmentation result = segmenter.segment(scene.frame, &scene.panoptic);
  ASSERT_EQ(result.surface_list.size(), 1u);
  EXPECT_EQ(result.surface_list[0].panoptic_segment, 0);
  EXPECT_EQ(result.surface_list[0].category, 0);
  EXPECT_EQ(result.surfaces, result.geometric);
  // Same as no panoptic frame at all.
  PanopticGeometricSegmenter plain({}, {});
  EXPECT_EQ(plain.segment(scene.frame, nullptr).surfaces, result.surfaces);
}

TEST(SurfaceFusion, PanopticOfWrongSizeThrows) {
  BandedWall scene;
  scene.panoptic.segment_ids = LabelImage(320, 240);
  PanopticGeometricSegmenter segmenter({}, {});
  try {
    segmenter.segment(scene.frame, &scene.panoptic);
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("segment_ids is 320x240"), std::string::npos) << e.what();
  }
  // Repeated ids are an input error too.
  BandedWall twice;
  twice.panoptic.segments.push_back({7, 5, 62, true, 0.1f});
  EXPECT_THROW(segmenter.segment(twice.frame, &twice.panoptic), Error);
}

TEST(SurfaceFusion, DeterministicAcrossRunsAndThreads) {
  // Box before a wall over a floor, with pseudo-random depth noise and a mask over the box.
  RgbdFrame frame =
      render([](double x, double y) { return std::min(boxBeforeWall(x, y), floorAndWall(x, y)); });
  uint32_t state = 12345;
  for (size_t i = 0; i < frame.depth.size(); ++i) {
    state = state * 1664525u + 1013904223u;
    frame.depth.data()[i] += static_cast<uint16_t>(state >> 29);  // 0..0.7 mm
  }
  BandedWall masks;
  PanopticGeometricSegmenter segmenter({}, {});
  const FrameSegmentation first = segmenter.segment(frame, &masks.panoptic);
  const FrameSegmentation second = segmenter.segment(frame, &masks.panoptic);
  DepthSegmentationConfig threaded;
  threaded.num_threads = 2;
  PanopticGeometricSegmenter parallel(threaded, {});
  const FrameSegmentation third = parallel.segment(frame, &masks.panoptic);
  EXPECT_GE(first.surface_list.size(), 4u);
  for (const FrameSegmentation* other : {&second, &third}) {
    EXPECT_EQ(first.geometric, other->geometric);
    EXPECT_EQ(first.surfaces, other->surfaces);
    ASSERT_EQ(first.surface_list.size(), other->surface_list.size());
    for (size_t k = 0; k < first.surface_list.size(); ++k) {
      const Surface& a = first.surface_list[k];
      const Surface& b = other->surface_list[k];
      EXPECT_EQ(a.id, b.id);
      EXPECT_EQ(a.geometric_segment, b.geometric_segment);
      EXPECT_EQ(a.panoptic_segment, b.panoptic_segment);
      EXPECT_EQ(a.num_pixels, b.num_pixels);
      EXPECT_EQ(a.confidence, b.confidence);
    }
  }
  EXPECT_EQ(segmenter.minConvexity(), parallel.minConvexity());
  // Segmenting into a reused output (after another frame) gives the same result.
  FrameSegmentation reused;
  segmenter.segment(render(boxBeforeWall), nullptr, &reused);
  segmenter.segment(frame, &masks.panoptic, &reused);
  EXPECT_EQ(reused.geometric, first.geometric);
  EXPECT_EQ(reused.surfaces, first.surfaces);
  EXPECT_EQ(reused.surface_list.size(), first.surface_list.size());
}

TEST(SurfaceFusion, KeptGeometricSegmentsAreTakenOnlyFromTheSameConfig) {
  RgbdFrame frame =
      render([](double x, double y) { return std::min(boxBeforeWall(x, y), floorAndWall(x, y)); });
  BandedWall masks;
  DepthSegmentationConfig config;
  PanopticGeometricSegmenter first(config, {});
  const FrameSegmentation computed = first.segment(frame, &masks.panoptic);
  EXPECT_FALSE(first.keptLast());
  ASSERT_GE(computed.surface_list.size(), 4u);

  // Kept from that run: the same surfaces without the depth stages.
  GeometricSegments kept{computed.geometric, config.key()};
  PanopticGeometricSegmenter second(config, {});
  FrameSegmentation out;
  second.segment(frame, &masks.panoptic, &out, &kept);
  EXPECT_TRUE(second.keptLast());
  EXPECT_EQ(out.geometric, computed.geometric);
  EXPECT_EQ(out.surfaces, computed.surfaces);
  ASSERT_EQ(out.surface_list.size(), computed.surface_list.size());
  for (size_t k = 0; k < out.surface_list.size(); ++k) {
    EXPECT_EQ(out.surface_list[k].num_pixels, computed.surface_list[k].num_pixels);
    EXPECT_EQ(out.surface_list[k].panoptic_segment, computed.surface_list[k].panoptic_segment);
  }
  // They are what is used: altered segments give other surfaces.
  GeometricSegments altered = kept;
  for (int v = 0; v < 240; ++v) {
    for (int u = 0; u < 640; ++u) altered.ids(u, v) = 0;
  }
  second.segment(frame, &masks.panoptic, &out, &altered);
  EXPECT_TRUE(second.keptLast());
  EXPECT_FALSE(out.surfaces == computed.surfaces);

  // Another config's segments, or another size, are not taken: computed again.
  DepthSegmentationConfig other = config;
  other.min_convexity_threshold = 0.95f;
  EXPECT_NE(other.key(), config.key());
  DepthSegmentationConfig threaded = config;
  threaded.num_threads = 2;
  EXPECT_EQ(threaded.key(), config.key());  // threads do not change the segments
  GeometricSegments foreign{altered.ids, other.key()};
  second.segment(frame, &masks.panoptic, &out, &foreign);
  EXPECT_FALSE(second.keptLast());
  EXPECT_EQ(out.surfaces, computed.surfaces);
  GeometricSegments small{LabelImage(320, 240), config.key()};
  second.segment(frame, &masks.panoptic, &out, &small);
  EXPECT_FALSE(second.keptLast());
  EXPECT_EQ(out.surfaces, computed.surfaces);
}

TEST(DepthSegmentation, RealSevenScenesFrameIsSane) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  const cv::Mat png =
      cv::imread(test::dataDir("7scenes-200/frame-000000.depth.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(png.type(), CV_16UC1);
  ASSERT_EQ(png.cols, 640);
  ASSERT_EQ(png.rows, 480);
  RgbdFrame frame;
  frame.camera = PinholeCamera{585.0, 585.0, 320.0, 240.0, 640, 480};
  frame.depth_scale_m = 0.001;
  frame.depth = DepthImage(640, 480);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) frame.depth(u, v) = png.at<uint16_t>(v, u);
  }
  PanopticGeometricSegmenter segmenter({}, {});
  const FrameSegmentation result = segmenter.segment(frame, nullptr);

  const SegmentStats s = stats(result.geometric);
  EXPECT_GE(s.area_px.size(), 10u);
  expectConsecutiveIds(s);
  for (const auto& [id, area] : s.area_px) EXPECT_GE(area, 100) << id;
  int valid = 0, segmented = 0;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      // 7-Scenes marks missing depth with 65535, beyond max_depth_m.
      const bool ok = frame.depth(u, v) > 0 && frame.depth(u, v) * 0.001 <= 10.0;
      valid += ok;
      segmented += ok && result.geometric(u, v) > 0;
      if (!ok) {
        ASSERT_EQ(result.geometric(u, v), 0);
      }
    }
  }
  EXPECT_GE(segmented, valid / 2) << segmented << " of " << valid;
  // Geometry only: one background surface per segment of at least min_surface_px.
  expectConsecutiveIds(stats(result.surfaces));
  for (const Surface& surface : result.surface_list) {
    EXPECT_EQ(surface.panoptic_segment, 0);
    EXPECT_EQ(surface.num_pixels, s.area_px.at(surface.geometric_segment));
  }
}

}  // namespace
}  // namespace panmap
