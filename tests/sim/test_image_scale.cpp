#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/sim/sequence.h"

namespace panmap {
namespace {

// Where a camera-frame point lands, as a share of the image (pixel u covers [u - 0.5, u + 0.5]).
Eigen::Vector2d imageShare(const PinholeCamera& c, const Eigen::Vector3d& p_C) {
  return {(c.fx * p_C.x() / p_C.z() + c.cx + 0.5) / c.width,
          (c.fy * p_C.y() / p_C.z() + c.cy + 0.5) / c.height};
}

TEST(SynthImageScale, TheCameraKeepsItsFieldOfView) {
  const SynthConfig base;
  const SynthConfig big = scaledImage(base, 2.0), small = scaledImage(base, 0.5);
  EXPECT_EQ(big.camera.width, 1280);
  EXPECT_EQ(big.camera.height, 960);
  EXPECT_DOUBLE_EQ(big.camera.fx, 1050.0);
  EXPECT_DOUBLE_EQ(big.camera.cx, 639.5);
  EXPECT_EQ(small.camera.width, 320);
  EXPECT_EQ(small.camera.height, 240);
  EXPECT_DOUBLE_EQ(small.camera.fy, 262.5);
  EXPECT_DOUBLE_EQ(small.camera.cy, 119.5);
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.3, -0.2, 2.0), Eigen::Vector3d(-1, 0.7, 1.5)}) {
    EXPECT_TRUE(imageShare(big.camera, p).isApprox(imageShare(base.camera, p), 1e-12));
    EXPECT_TRUE(imageShare(small.camera, p).isApprox(imageShare(base.camera, p), 1e-12));
  }
}

TEST(SynthImageScale, NoiseLengthsScaleWithTheImageAndAreasWithItsSquare) {
  SynthConfig base;
  base.masks = SegmenterNoiseConfig::fromPreset("m2f");
  const SynthConfig big = scaledImage(base, 2.0);
  EXPECT_DOUBLE_EQ(big.masks.boundary_mean_px, 2.0 * base.masks.boundary_mean_px);
  EXPECT_EQ(big.masks.boundary_grid_px, 2 * base.masks.boundary_grid_px);
  EXPECT_EQ(big.masks.merge_min_contact_px, 2 * base.masks.merge_min_contact_px);
  EXPECT_EQ(big.masks.miss_small_px, 4 * base.masks.miss_small_px);
  EXPECT_EQ(big.masks.miss_large_px, 4 * base.masks.miss_large_px);
  EXPECT_EQ(big.masks.false_positive_min_area_px, 4 * base.masks.false_positive_min_area_px);
  EXPECT_EQ(big.masks.false_positive_max_area_px, 4 * base.masks.false_positive_max_area_px);
  EXPECT_EQ(big.masks.stats_min_px, 4 * base.masks.stats_min_px);
  EXPECT_EQ(big.min_view_px, 4 * base.min_view_px);
  EXPECT_DOUBLE_EQ(big.depth.lateral_sigma_px, 2.0 * base.depth.lateral_sigma_px);
  EXPECT_EQ(big.depth.correlation_px, 2 * base.depth.correlation_px);
  // What is not in pixels stays.
  EXPECT_DOUBLE_EQ(big.masks.confusion_probability, base.masks.confusion_probability);
  EXPECT_DOUBLE_EQ(big.depth.axial_sigma_b_m, base.depth.axial_sigma_b_m);
  // Rounded, never below one pixel.
  const SynthConfig tiny = scaledImage(base, 0.25);
  EXPECT_EQ(tiny.masks.merge_min_contact_px, 1);
  EXPECT_EQ(tiny.camera.width, 160);
  EXPECT_NO_THROW(big.check());
  EXPECT_NO_THROW(tiny.check());
}

TEST(SynthImageScale, ABadScaleOrADepthPatternIsAClearError) {
  EXPECT_THROW(scaledImage(SynthConfig(), 5.0), Error);
  EXPECT_THROW(scaledImage(SynthConfig(), 0.0), Error);
  SynthConfig patterned;
  patterned.depth_pattern =
      DepthCalibration(640, 480, 2, 1, 2, 5.0, {0.004f, -0.002f, 0.004f, -0.002f});
  try {
    scaledImage(patterned, 2.0);
    FAIL() << "a depth pattern was scaled";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("depth pattern"), std::string::npos);
  }
}

}  // namespace
}  // namespace panmap
