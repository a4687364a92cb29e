#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/io/dataset_reader.h"
#include "test_helpers.h"

namespace panmap {
namespace {

TEST(Tum, AssociatesByNearestTimestamp) {
  const auto reader = openDataset(test::fixtureDir("tum_tiny"), DatasetOptions{});
  EXPECT_EQ(reader->layoutName(), "tum");
  // Depth at 1.070 is 37 ms from the nearest colour image (tolerance 20 ms): dropped.
  EXPECT_EQ(reader->size(), 3u);
  EXPECT_EQ(reader->unmatchedFrames(), 1u);

  const DatasetFrame f0 = reader->read(0);
  EXPECT_EQ(f0.rgbd.utime, 1005000);
  EXPECT_EQ(f0.color_stem, "1.000000");
  EXPECT_DOUBLE_EQ(f0.rgbd.depth_scale_m, 1.0 / 5000.0);
  EXPECT_DOUBLE_EQ(f0.rgbd.camera.fx, 10.0);
  EXPECT_EQ(f0.rgbd.camera.width, 8);
  EXPECT_EQ(f0.rgbd.depth(0, 0), 0);
  EXPECT_EQ(f0.rgbd.depth(3, 2), 5003);
  EXPECT_EQ(f0.rgbd.color(5, 1), (Rgb8{5, 20, 200}));
  // Midway between 0.995 (x = 0) and 1.015 (x = 0.2).
  ASSERT_TRUE(f0.T_W_C.has_value());
  EXPECT_NEAR(f0.T_W_C->translation().x(), 0.1, 1e-9);

  const DatasetFrame f1 = reader->read(1);
  EXPECT_EQ(f1.color_stem, "1.033000");
  EXPECT_EQ(f1.rgbd.depth(1, 1), 10001);
  ASSERT_TRUE(f1.T_W_C.has_value());
  EXPECT_TRUE(f1.T_W_C->translation().isApprox(Eigen::Vector3d(0.2, 0.0, 0.5), 1e-9));
  const Eigen::AngleAxisd yaw(f1.T_W_C->linear());
  EXPECT_NEAR(yaw.angle(), M_PI / 4, 1e-9);  // slerp halfway to 90 degrees

  // 1.101 is 56 ms past the last ground-truth sample.
  const DatasetFrame f2 = reader->read(2);
  EXPECT_FALSE(f2.T_W_C.has_value());
  EXPECT_NE(f2.pose_problem.find("groundtruth.txt"), std::string::npos);
}

TEST(Tum, WiderToleranceMatchesMore) {
  DatasetOptions options;
  options.tum_max_dt_s = 0.04;
  EXPECT_EQ(openDataset(test::fixtureDir("tum_tiny"), options)->size(), 4u);
}

TEST(Tum, IntrinsicsOverride) {
  DatasetOptions options;
  options.intrinsics = Eigen::Vector4d(20, 21, 4, 3);
  const DatasetFrame f = openDataset(test::fixtureDir("tum_tiny"), options)->read(0);
  EXPECT_DOUBLE_EQ(f.rgbd.camera.fy, 21.0);
  options.intrinsics = Eigen::Vector4d(-1, 21, 4, 3);
  EXPECT_THROW(openDataset(test::fixtureDir("tum_tiny"), options), Error);
}

}  // namespace
}  // namespace panmap
