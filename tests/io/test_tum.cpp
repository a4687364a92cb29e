#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "panmap/core/error.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/timestamps.h"
#include "panmap/io/tum_trajectory.h"
#include "test_helpers.h"

namespace panmap {
namespace {

// Times counted from the start of a recording in us or ns are small numbers that read as
// seconds by magnitude: frames 33,333 s apart, and nothing matched. The step between rows
// tells their unit.
TEST(Timestamps, RelativeTimesInFinerUnitsAreJudgedByTheirStep) {
  EXPECT_STREQ(timestampUnitOf({0, 33333333, 66666667, 100000000}).name, "nanoseconds");
  EXPECT_STREQ(timestampUnitOf({0, 33333, 66667, 100000}).name, "microseconds");
  EXPECT_STREQ(timestampUnitOf({0, 500, 1000, 1500}).name, "milliseconds");  // 2 Hz keyframes
  EXPECT_STREQ(timestampUnitOf({0, 33, 67, 100}).name, "seconds");  // ms at 30 Hz: not told
  EXPECT_STREQ(timestampUnitOf({0, 3, 6, 9}).name, "seconds");      // frame numbers
  EXPECT_STREQ(timestampUnitOf({1305031102.175, 1305031102.211}).name, "seconds");
  EXPECT_STREQ(timestampUnitOf({1305031102175.0, 1305031102211.0}).name, "milliseconds");
  EXPECT_STREQ(timestampUnitOf({}).name, "seconds");
  EXPECT_STREQ(timestampUnitOf({5.0, 5.0, 5.0}).name, "seconds");  // no step at all
  test::TempDir dir;
  std::ofstream(dir.path("t.txt")) << "0 0 0 0 0 0 0 1\n"
                                      "33333333 0.1 0 0 0 0 0 1\n"
                                      "66666667 0.2 0 0 0 0 0 1\n";
  const std::vector<StampedPose> poses = readTumTrajectory(dir.path("t.txt"));
  ASSERT_EQ(poses.size(), 3u);
  EXPECT_EQ(poses[1].utime, 33333);
  EXPECT_EQ(poses[2].utime, 66667);
}

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

// A two-frame 640x480 TUM folder at `dir` (no intrinsics file), every depth pixel `depth`.
void writeTumFolder(const std::string& dir, uint16_t depth) {
  namespace fs = std::filesystem;
  fs::create_directories(dir + "/rgb");
  fs::create_directories(dir + "/depth");
  std::ofstream rgb(dir + "/rgb.txt"), depth_list(dir + "/depth.txt");
  for (const char* t : {"1.000000", "1.033000"}) {
    writeFileBytes(dir + "/rgb/" + t + ".png", encodePng(ColorImage(640, 480, Rgb8{90, 90, 90})));
    writeFileBytes(dir + "/depth/" + t + ".png", encodeDepthPng(DepthImage(640, 480, depth)));
    rgb << t << " rgb/" << t << ".png\n";
    depth_list << t << " depth/" << t << ".png\n";
  }
}

std::string joined(const std::vector<std::string>& notes) {
  std::string out;
  for (const std::string& n : notes) out += n + "\n";
  return out;
}

TEST(Tum, OnlyTheSequenceFoldersOwnNameNamesItsCamera) {
  test::TempDir dir;
  // A sequence named as TUM names them, below a parent that names another camera.
  const std::string fr3 = dir.path("freiburg1_copies/rgbd_dataset_freiburg3_office");
  writeTumFolder(fr3, 7500);
  const auto reader = openDataset(fr3, DatasetOptions{});
  EXPECT_DOUBLE_EQ(reader->read(0).rgbd.camera.fx, 535.4);
  EXPECT_NE(joined(reader->notes())
                .find("intrinsics: TUM's freiburg3 intrinsics (the folder is "
                      "named rgbd_dataset_freiburg3_office"),
            std::string::npos)
      << joined(reader->notes());
  // A user's own recording below a folder whose name merely contains "freiburg2...".
  const std::string own = dir.path("freiburg2024_recordings/my_kinect");
  writeTumFolder(own, 7500);
  try {
    openDataset(own, DatasetOptions{});
    FAIL() << "a parent folder's name chose the intrinsics";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("names no freiburg camera"), std::string::npos)
        << e.what();
  }
  const std::string year = dir.path("rgbd_dataset_freiburg2024");
  writeTumFolder(year, 7500);
  EXPECT_THROW(openDataset(year, DatasetOptions{}), Error);
}

TEST(Tum, DepthInMillimetresIsNamed) {
  test::TempDir dir;
  // 1.5 m everywhere: 7500 in TUM's 1/5000 m is a Kinect's range, 1500 is not.
  const std::string tum = dir.path("rgbd_dataset_freiburg1_a");
  writeTumFolder(tum, 7500);
  const std::string tum_notes = joined(openDataset(tum, DatasetOptions{})->notes());
  EXPECT_NE(tum_notes.find("depth scale: 1/5000 m per unit (TUM), TUM's (median 1.5 m over 2 "
                           "images"),
            std::string::npos)
      << tum_notes;
  EXPECT_EQ(tum_notes.find("WARNING"), std::string::npos) << tum_notes;
  const std::string mm = dir.path("rgbd_dataset_freiburg1_b");
  writeTumFolder(mm, 1500);
  const auto reader = openDataset(mm, DatasetOptions{});
  const std::string mm_notes = joined(reader->notes());
  EXPECT_NE(mm_notes.find("WARNING: a median this near is closer than a Kinect measures: if the "
                          "images are in millimetres (median 1.5 m), pass --depth-scale 0.001"),
            std::string::npos)
      << mm_notes;
  EXPECT_DOUBLE_EQ(reader->read(0).rgbd.depth_scale_m, 1.0 / 5000.0);  // named, not changed
  DatasetOptions given;
  given.depth_scale_m = 0.001;
  const auto fixed = openDataset(mm, given);
  EXPECT_DOUBLE_EQ(fixed->read(0).rgbd.depth_scale_m, 0.001);
  EXPECT_NE(joined(fixed->notes()).find("depth scale: 0.001 m per unit (mm) (given)"),
            std::string::npos);
}

TEST(Tum, ListsAndIntrinsicsAreReadAsTheOtherLayoutsReadThem) {
  test::TempDir dir;
  const std::string seq = dir.path("my_kinect");
  writeTumFolder(seq, 7500);
  // An indented comment and a blank line of spaces, as pose files may have them.
  std::ofstream(seq + "/rgb.txt")
      << "  # colour\n   \n1.000000 rgb/1.000000.png\n1.033000 rgb/1.033000.png\n";
  // "fx fy cx cy", as the folder layout accepts.
  std::ofstream(seq + "/camera-intrinsics.txt") << "525 526 319.5 239.5\n";
  const auto reader = openDataset(seq, DatasetOptions{});
  EXPECT_EQ(reader->size(), 2u);
  const PinholeCamera camera = reader->read(0).rgbd.camera;
  EXPECT_DOUBLE_EQ(camera.fx, 525.0);
  EXPECT_DOUBLE_EQ(camera.fy, 526.0);
  EXPECT_DOUBLE_EQ(camera.cx, 319.5);
  EXPECT_DOUBLE_EQ(camera.cy, 239.5);
}

}  // namespace
}  // namespace panmap
