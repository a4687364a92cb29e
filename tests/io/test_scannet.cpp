#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/io/image_codec.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;

TEST(ScanNetExport, RegistersColourToDepth) {
  PANMAP_REQUIRE_DATA("scannet-export-3");
  const auto reader = openDataset(test::dataDir("scannet-export-3"), DatasetOptions{});
  EXPECT_EQ(reader->layoutName(), "scannet");
  ASSERT_EQ(reader->size(), 3u);
  EXPECT_TRUE(reader->invalidPosesExpected());
  const DatasetFrame f = reader->read(1);
  EXPECT_EQ(f.rgbd.frame_id, 1);
  EXPECT_EQ(f.rgbd.utime, 33333);
  EXPECT_DOUBLE_EQ(f.rgbd.camera.fx, 575.665710);  // intrinsic_depth.txt
  EXPECT_DOUBLE_EQ(f.rgbd.camera.cy, 240.126617);
  EXPECT_EQ(f.rgbd.color.width(), 640);
  EXPECT_EQ(f.rgbd.color.height(), 480);
  EXPECT_EQ(f.color_source_width, 1296);
  EXPECT_EQ(f.color_source_height, 968);
  EXPECT_TRUE(f.color_jpeg.empty());  // resampled: must be re-encoded
  ASSERT_TRUE(f.T_W_C.has_value());
  EXPECT_NEAR(f.T_W_C->translation().x(), 4.086335, 1e-9);

  // Reprojection through depth and the metadata's colorToDepthExtrinsics (p_D = E p_C).
  Eigen::Matrix4d E;
  E << 0.999263, -0.010031, 0.037048, -0.038549, 0.009933, 0.999947, 0.002817, -0.004287, -0.037074,
      -0.002447, 0.999310, -0.020574, 0, 0, 0, 1;
  const Eigen::Matrix4d T_C_D = E.inverse();
  int checked = 0;
  for (int v = 10; v < 480; v += 97) {
    for (int u = 10; u < 640; u += 131) {
      const double z = f.rgbd.depth(u, v) * 0.001;
      if (z <= 0.0) continue;
      const Eigen::Vector4d p_D(z * (u - 320.287018) / 575.665710,
                                z * (v - 240.126617) / 578.051880, z, 1.0);
      const Eigen::Vector4d p_C = T_C_D * p_D;
      const double uc = 1165.723022 * p_C.x() / p_C.z() + 649.094971;
      const double vc = 1165.738037 * p_C.y() / p_C.z() + 484.765015;
      EXPECT_NEAR(f.color_map_u(u, v), uc, 1e-3);
      EXPECT_NEAR(f.color_map_v(u, v), vc, 1e-3);
      // The colour camera sees the point close to where a plain resize would put it.
      EXPECT_NEAR(f.color_map_u(u, v), (u + 0.5) * 1296.0 / 640.0 - 0.5, 80.0);
      ++checked;
    }
  }
  EXPECT_GT(checked, 10);
}

TEST(ScanNetExport, ResizeRegistrationIsAffine) {
  PANMAP_REQUIRE_DATA("scannet-export-3");
  DatasetOptions options;
  options.registration = ColorRegistration::kResize;
  const DatasetFrame f = openDataset(test::dataDir("scannet-export-3"), options)->read(0);
  EXPECT_FLOAT_EQ(f.color_map_u(0, 0), 0.5f * 1296.0f / 640.0f - 0.5f);
  EXPECT_FLOAT_EQ(f.color_map_v(639, 479), 479.5f * 968.0f / 480.0f - 0.5f);
  // Masks at colour resolution come through the same map, nearest neighbour.
  LabelImage mask(1296, 968, 0);
  for (int v = 0; v < 968; ++v) {
    for (int u = 648; u < 1296; ++u) mask(u, v) = 9;
  }
  const LabelImage registered = registerLabelsToDepth(mask, f, "mask");
  EXPECT_EQ(registered(319, 200), 0);
  EXPECT_EQ(registered(320, 200), 9);
  EXPECT_THROW(registerLabelsToDepth(LabelImage(640, 480), f, "mask"), Error);
}

TEST(ScanNetExport, PosesReadAloneAreThoseOfTheFrames) {
  PANMAP_REQUIRE_DATA("scannet-export-3");
  test::TempDir dir;
  test::makeScanNetExportWithInfPose(dir);
  const auto reader = openDataset(dir.path(), DatasetOptions{});
  for (size_t i = 0; i < reader->size(); ++i) {
    const DatasetPose p = reader->pose(i);
    const DatasetFrame f = reader->read(i);
    EXPECT_EQ(p.utime, f.rgbd.utime);
    EXPECT_EQ(p.frame_id, f.rgbd.frame_id);
    ASSERT_EQ(p.T_W_C.has_value(), f.T_W_C.has_value()) << i;
    if (p.T_W_C) EXPECT_TRUE(p.T_W_C->isApprox(*f.T_W_C, 0.0));
    EXPECT_EQ(p.problem, f.pose_problem);
  }
  EXPECT_FALSE(reader->pose(1).T_W_C.has_value());  // the -inf rows
}

TEST(ScanNetExport, InfPoseIsReportedNotRead) {
  PANMAP_REQUIRE_DATA("scannet-export-3");
  test::TempDir dir;
  test::makeScanNetExportWithInfPose(dir);
  const auto reader = openDataset(dir.path(), DatasetOptions{});
  EXPECT_TRUE(reader->read(0).T_W_C.has_value());
  const DatasetFrame bad = reader->read(1);
  EXPECT_FALSE(bad.T_W_C.has_value());
  EXPECT_NE(bad.pose_problem.find("pose/1.txt"), std::string::npos) << bad.pose_problem;
  EXPECT_TRUE(reader->read(2).T_W_C.has_value());
}

// A frame whose depth image is missing was left out of the import without a word.
TEST(ScanNetExport, AColourImageWithoutDepthIsCounted) {
  PANMAP_REQUIRE_DATA("scannet-export-3");
  test::TempDir dir;
  const std::string src = test::dataDir("scannet-export-3");
  for (const char* sub : {"color", "pose", "intrinsic"}) {
    fs::create_directory_symlink(src + "/" + sub, dir.path(sub));
  }
  fs::create_symlink(src + "/scene0707_00.txt", dir.path("scene0707_00.txt"));
  fs::create_directory(dir.path("depth"));
  for (const char* name : {"0.png", "2.png"}) {
    fs::create_symlink(src + "/depth/" + name, dir.path("depth/") + name);
  }
  const auto reader = openDataset(dir.path(), DatasetOptions{});
  EXPECT_EQ(reader->size(), 2u);
  EXPECT_EQ(reader->unmatchedFrames(), 1u);
  EXPECT_EQ(reader->unmatchedWhat(), "colour images without a depth image (first: color/1.jpg)");
}

TEST(ScanNetExport, MissingDepthIntrinsics) {
  PANMAP_REQUIRE_DATA("scannet-export-3");
  test::TempDir dir;
  const std::string src = test::dataDir("scannet-export-3");
  for (const char* sub : {"color", "depth", "pose"})
    fs::create_directory_symlink(src + "/" + sub, dir.path(sub));
  fs::create_directory(dir.path("intrinsic"));
  fs::create_symlink(src + "/intrinsic/intrinsic_color.txt",
                     dir.path("intrinsic/intrinsic_color.txt"));
  try {
    openDataset(dir.path(), DatasetOptions{});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("intrinsic_depth.txt"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace panmap
