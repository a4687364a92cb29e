#include <cmath>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/sim/depth_noise.h"

namespace panmap {
namespace {

// A rendered view of a fronto-parallel wall at z_m, facing the camera.
RenderedView wall(double z_m, float cos_incidence = 1.0f) {
  RenderedView view;
  view.depth_m = Image<float>(320, 240, static_cast<float>(z_m));
  view.cos_incidence = Image<float>(320, 240, cos_incidence);
  return view;
}

TEST(DepthNoise, AxialSigmaFollowsNguyen) {
  const DepthNoiseConfig config;
  for (double z : {1.0, 2.0, 3.5}) {
    const DepthImage depth = simulateDepth(wall(z), config, 7);
    double sum = 0, sum2 = 0;
    size_t n = 0;
    for (size_t i = 0; i < depth.size(); ++i) {
      if (!depth.data()[i]) continue;
      const double d = depth.data()[i] * 0.001;
      sum += d;
      sum2 += d * d;
      ++n;
    }
    ASSERT_GT(n, depth.size() * 0.99);  // nothing to drop on a frontal wall
    const double mean = sum / n;
    const double sigma = std::sqrt(sum2 / n - mean * mean);
    const double expected = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
    // The correlated part has ~1200 independent control points here: the mean is good to
    // about sigma / 30.
    EXPECT_NEAR(mean, z, 0.1 * (0.0012 + 0.0019 * (z - 0.4) * (z - 0.4))) << z;
    // Quantisation (1 mm, variance 1/12 mm^2) adds a little at short range.
    EXPECT_NEAR(sigma, std::sqrt(expected * expected + 1e-6 / 12), 0.05 * expected) << z;
  }
}

TEST(DepthNoise, RangeAndGrazingDropouts) {
  const DepthNoiseConfig config;
  auto valid = [](const DepthImage& d) {
    size_t n = 0;
    for (size_t i = 0; i < d.size(); ++i) n += d.data()[i] != 0;
    return n;
  };
  EXPECT_EQ(valid(simulateDepth(wall(7.0), config, 1)), 0u);  // beyond max range
  EXPECT_EQ(valid(simulateDepth(wall(0.2), config, 1)), 0u);  // nearer than min range
  EXPECT_EQ(valid(simulateDepth(wall(2.0, std::cos(87.0 * M_PI / 180)), config, 1)), 0u);
  // Halfway between 70 and 85 degrees about half the pixels survive.
  const size_t half = valid(simulateDepth(wall(2.0, std::cos(77.5 * M_PI / 180)), config, 1));
  EXPECT_NEAR(static_cast<double>(half) / (320 * 240), 0.5, 0.05);
}

TEST(DepthNoise, EdgesLoseAboutHalfTheirPixelsAndJitter) {
  // Left half at 1 m, right half at 3 m: a vertical depth edge at u = 160.
  RenderedView view = wall(1.0);
  for (int v = 0; v < 240; ++v) {
    for (int u = 160; u < 320; ++u) view.depth_m(u, v) = 3.0f;
  }
  DepthNoiseConfig config;
  const DepthImage depth = simulateDepth(view, config, 3);
  size_t dropped_far_from_edge = 0, dropped_near_edge = 0, near_edge = 0;
  for (int v = 0; v < 240; ++v) {
    for (int u = 0; u < 320; ++u) {
      const bool near = std::abs(u - 159.5) < 3;
      near_edge += near;
      if (depth(u, v) == 0) (near ? dropped_near_edge : dropped_far_from_edge)++;
    }
  }
  EXPECT_EQ(dropped_far_from_edge, 0u);
  EXPECT_GT(dropped_near_edge, near_edge / 10);  // the two columns beside the step lose half
  EXPECT_LT(dropped_near_edge, near_edge * 2 / 3);
  config.enabled = false;
  const DepthImage exact = simulateDepth(view, config, 3);
  EXPECT_EQ(exact(159, 10), 1000);
  EXPECT_EQ(exact(160, 10), 3000);
}

TEST(DepthNoise, DeterministicPerSeed) {
  const RenderedView view = wall(2.0);
  const DepthNoiseConfig config;
  EXPECT_EQ(simulateDepth(view, config, 11), simulateDepth(view, config, 11));
  EXPECT_FALSE(simulateDepth(view, config, 11) == simulateDepth(view, config, 12));
  DepthNoiseConfig bad;
  bad.max_range_m = 0.1;
  EXPECT_THROW(bad.check(), Error);
}

}  // namespace
}  // namespace panmap
