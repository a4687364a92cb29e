#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "panmap/map/voxel.h"

namespace panmap {
namespace {

// IEEE binary16 bit patterns of values it holds exactly, and the round trip through float.
TEST(Float16, HoldsExactValuesBitForBit) {
  EXPECT_EQ(Float16(0.0f).bits(), 0x0000u);
  EXPECT_EQ(Float16(1.0f).bits(), 0x3C00u);
  EXPECT_EQ(Float16(-2.0f).bits(), 0xC000u);
  EXPECT_EQ(Float16(100.0f).bits(), 0x5640u);    // the default maximum weight
  EXPECT_EQ(Float16(65504.0f).bits(), 0x7BFFu);  // the largest finite value
  for (const float v : {0.0f, 1.0f, -2.0f, 0.5f, 100.0f, 0.0009765625f}) {
    EXPECT_EQ(static_cast<float>(Float16(v)), v);
  }
  EXPECT_TRUE(std::isnan(static_cast<float>(Float16(NAN))));
}

// Rounding to nearest keeps 11 significant bits: at most half a step, 2^-11 of the value, off,
// so 30 micrometres at the 8 cm truncation of 2 cm voxels; below 2^-14 (61 micrometres, where
// steps stop shrinking) at most 2^-25 m.
TEST(Float16, RoundsToNearestWithinHalfAStep) {
  float worst = 0.0f;
  for (int i = 1; i < 20000; ++i) {
    const float v = 0.08f * static_cast<float>(i) / 20000.0f;
    const float back = Float16(v);
    if (v < std::ldexp(1.0f, -14)) {
      EXPECT_LE(std::abs(back - v), std::ldexp(1.0f, -25)) << v;
      continue;
    }
    worst = std::max(worst, std::abs(back - v) / v);
    EXPECT_LE(std::abs(back - v), std::ldexp(v, -11)) << v;
  }
  EXPECT_GT(worst, std::ldexp(1.0f, -14));  // it does round (a float would not)
  EXPECT_LE(std::abs(static_cast<float>(Float16(0.08f)) - 0.08f), 3.1e-5f);
}

// Voxel expressions compute in float and round once when stored: a weighted mean of two stored
// values equals the float computation, rounded.
TEST(Float16, ArithmeticIsFloatArithmetic) {
  Voxel v;
  v.sdf_m = 0.0123f;
  v.weight = 7.0f;
  const float a = v.sdf_m, w = v.weight;
  const float mean = (v.sdf_m * v.weight + 0.02f * 1.0f) / (v.weight + 1.0f);
  EXPECT_EQ(mean, (a * w + 0.02f) / (w + 1.0f));
  v.sdf_m = mean;
  EXPECT_EQ(v.sdf_m.bits(), Float16(mean).bits());
  v.weight += 0.5f;
  EXPECT_EQ(static_cast<float>(v.weight), 7.5f);
  EXPECT_EQ(sizeof(Voxel), 8u);
  EXPECT_EQ(sizeof(VoxelVotes), 24u);
}

}  // namespace
}  // namespace panmap
