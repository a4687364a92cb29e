#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/sim/sequence.h"

namespace panmap {
namespace {

// A wall 2 m in front of an identity camera, wide enough to fill the image.
LabelledMesh wallAt2m() {
  LabelledMesh mesh;
  mesh.vertices = {{-5, -5, 2}, {5, -5, 2}, {5, 5, 2}, {-5, 5, 2}};
  mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  mesh.instance = {1, 1, 1, 1};
  mesh.semantic = {1, 1, 1, 1};
  return mesh;
}

SynthConfig smallExactConfig() {
  SynthConfig config;
  config.camera = PinholeCamera{131.25, 131.25, 79.5, 59.5, 160, 120};
  config.depth.enabled = false;  // rendered depth, quantised to 1 mm
  config.masks = SegmenterNoiseConfig::fromPreset("clean");
  config.poses = PoseDriftConfig::fromPreset("gt");
  return config;
}

// A calibration of two cells across, one down, the same at both depth knots (0 and 5 m): +4 mm
// on the left half's centre, -2 mm on the right's (as a real calibration: what to add to
// correct a reading).
DepthCalibration twoCellCalibration(int width, int height) {
  return DepthCalibration(width, height, 2, 1, 2, 5.0, {0.004f, -0.002f, 0.004f, -0.002f});
}

DepthImage renderDepth(const SynthConfig& config) {
  StampedPose pose;
  pose.utime = 1000000;
  SequenceSynthesizer synth(wallAt2m(), {pose}, config);
  return synth.frame(0).rgbd.depth;
}

TEST(SynthDepthPattern, TheSensorErrorIsTheCalibrationsNegativeTimesTheScale) {
  SynthConfig config = smallExactConfig();
  const DepthImage clean = renderDepth(config);
  ASSERT_EQ(clean(10, 60), 2000);
  config.depth_pattern = sensorDepthPattern(twoCellCalibration(160, 120), 0.5);
  const DepthImage patterned = renderDepth(config);
  // Left of the left cell's centre (u = 40) the left value holds, right of the right one's
  // (u = 120) the right one; half of -(+4 mm) and of -(-2 mm).
  for (int v : {0, 60, 119}) {
    EXPECT_EQ(patterned(10, v), clean(10, v) - 2) << v;
    EXPECT_EQ(patterned(150, v), clean(150, v) + 1) << v;
  }
  // Halfway between the centres (u = 80): the mean of -2 and +1 mm is -0.5 mm, rounded.
  EXPECT_NEAR(static_cast<int>(patterned(80, 60)) - static_cast<int>(clean(80, 60)), 0, 1);
}

TEST(SynthDepthPattern, ScaleZeroAndTheEmptyCalibrationChangeNothing) {
  SynthConfig config = smallExactConfig();
  const DepthImage clean = renderDepth(config);
  config.depth_pattern = sensorDepthPattern(twoCellCalibration(160, 120), 0.0);
  const DepthImage unchanged = renderDepth(config);
  EXPECT_TRUE(std::equal(clean.data(), clean.data() + clean.size(), unchanged.data()));
  EXPECT_TRUE(sensorDepthPattern(DepthCalibration(), 2.0).empty());
}

TEST(SynthDepthPattern, APatternOfAnotherImageSizeOrABadScaleIsAClearError) {
  SynthConfig config = smallExactConfig();
  config.depth_pattern = sensorDepthPattern(twoCellCalibration(640, 480), 1.0);
  try {
    config.check();
    FAIL() << "a 640x480 pattern on a 160x120 camera was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("640x480"), std::string::npos) << e.what();
  }
  EXPECT_THROW(sensorDepthPattern(twoCellCalibration(160, 120), -1.0), Error);
  EXPECT_THROW(sensorDepthPattern(twoCellCalibration(160, 120), std::nan("")), Error);
}

}  // namespace
}  // namespace panmap
