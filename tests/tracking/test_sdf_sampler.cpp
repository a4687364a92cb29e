#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "analytic_tsdf.h"
#include "panmap/map/interpolation.h"
#include "panmap/tracking/sdf_sampler.h"

namespace panmap {
namespace {

// A sphere of radius 0.5 m around a point near the origin, so that blocks of negative index
// and block borders are crossed; the band leaves holes (unobserved voxels) inside and out.
TEST(SdfSampler, BitIdenticalToInterpolateSdf) {
  TsdfMap map(TsdfMap::Config{0.01f});
  const Eigen::Vector3f centre(0.03f, -0.02f, 0.01f);
  test::fillAnalyticTsdf(
      Eigen::AlignedBox3f(Eigen::Vector3f::Constant(-0.6f), Eigen::Vector3f::Constant(0.6f)), 0.04f,
      [&](const Eigen::Vector3f& p) { return (p - centre).norm() - 0.5f; }, &map);
  SdfSampler sampler(map);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uniform(-0.6f, 0.6f);
  int valid = 0, invalid = 0;
  for (int i = 0; i < 200000; ++i) {
    const Eigen::Vector3f p(uniform(rng), uniform(rng), uniform(rng));
    float a = 0.0f, b = 0.0f;
    Eigen::Vector3f ga, gb;
    const bool ok_a = interpolateSdf(map, p, &a, &ga);
    const bool ok_b = sampler.sample(p, &b, &gb);
    ASSERT_EQ(ok_a, ok_b) << p.transpose();
    if (!ok_a) {
      ++invalid;
      continue;
    }
    ++valid;
    ASSERT_EQ(a, b) << p.transpose();
    ASSERT_EQ(ga, gb) << p.transpose();
  }
  EXPECT_GT(valid, 5000);  // both outcomes were exercised
  EXPECT_GT(invalid, 5000);
}

// A point's cell is reused while the point stays in it and refilled when it leaves (also
// into and out of unobserved voxels): the results never differ from a fresh lookup.
TEST(SdfSampler, CellsGiveTheSameBits) {
  TsdfMap map(TsdfMap::Config{0.01f});
  test::fillAnalyticTsdf(
      Eigen::AlignedBox3f(Eigen::Vector3f::Constant(-0.3f), Eigen::Vector3f::Constant(0.3f)), 0.03f,
      [](const Eigen::Vector3f& p) { return p.z() - 0.05f; }, &map);
  SdfSampler sampler(map);
  std::mt19937 rng(5);
  std::normal_distribution<float> step(0.0f, 0.002f);
  SdfSampler::Cell cell;
  Eigen::Vector3f p(0.01f, -0.02f, 0.05f);
  int valid = 0, invalid = 0;
  for (int i = 0; i < 20000; ++i) {
    p += Eigen::Vector3f(step(rng), step(rng), step(rng));
    p.z() = std::clamp(p.z(), 0.0f, 0.1f);  // wander through the band and out of it
    float a = 0.0f, b = 0.0f;
    Eigen::Vector3f ga, gb;
    const bool ok_a = sampler.sample(p, &a, &ga);
    ASSERT_EQ(ok_a, sampler.sample(p, &b, &gb, &cell)) << p.transpose();
    if (!ok_a) {
      ++invalid;
      continue;
    }
    ++valid;
    ASSERT_EQ(a, b);
    ASSERT_EQ(ga, gb);
  }
  EXPECT_GT(valid, 1000);
  EXPECT_GT(invalid, 1000);
}

TEST(SdfSampler, EmptyMapHasNoSamples) {
  const TsdfMap map(TsdfMap::Config{0.02f});
  SdfSampler sampler(map);
  float sdf = 0.0f;
  EXPECT_FALSE(sampler.sample(Eigen::Vector3f(0.1f, 0.2f, 0.3f), &sdf, nullptr));
}

}  // namespace
}  // namespace panmap
