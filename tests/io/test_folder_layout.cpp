// The generic RGB-D folder layout (rgb/ or color/, depth/, an intrinsics file, poses) and the
// auto-detection's error, on tiny folders written by the tests.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/pose_list.h"
#include "panmap/io/text_files.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

// Depth value `value` everywhere but pixel (0, 0) (no depth); colour encodes the frame.
void writeFrame(const std::string& rgb, const std::string& depth, int index, uint16_t value,
                int color_width = 8, int color_height = 6) {
  DepthImage d(8, 6, value);
  d(0, 0) = 0;
  writeFileBytes(depth, encodeDepthPng(d));
  ColorImage c(color_width, color_height, Rgb8{static_cast<uint8_t>(10 * index), 20, 30});
  writeFileBytes(rgb, encodePng(c));
}

// The layout of the issue: rgb/*.png, depth/*.png (mm), intrinsic.txt (4x4), gt_pose.txt (TUM
// with frame numbers in its time column); frame i at x = 0.1 i, yawed by 10 i degrees.
void makeIssueFolder(const test::TempDir& dir, int frames, uint16_t depth_value = 2000) {
  fs::create_directory(dir.path("rgb"));
  fs::create_directory(dir.path("depth"));
  std::ofstream poses(dir.path("gt_pose.txt"));
  poses.precision(17);
  poses << "# timestamp tx ty tz qx qy qz qw\n";
  for (int i = 0; i < frames; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    writeFrame(dir.path("rgb/") + name, dir.path("depth/") + name, i, depth_value);
    const double half = 0.5 * (10.0 * i) * M_PI / 180.0;
    poses << i << " " << 0.1 * i << " 0 1 0 0 " << std::sin(half) << " " << std::cos(half) << "\n";
  }
  writeText(dir.path("intrinsic.txt"), "5 0 4 0\n0 6 3 0\n0 0 1 0\n0 0 0 1\n");
}

TEST(FolderLayout, ImportsTheCommonExportWithoutFlags) {
  test::TempDir dir;
  makeIssueFolder(dir, 3);
  const auto reader = openDataset(dir.path(), DatasetOptions{});
  EXPECT_EQ(reader->layoutName(), "folder");
  ASSERT_EQ(reader->size(), 3u);
  const DatasetFrame f = reader->read(2);
  EXPECT_EQ(f.rgbd.frame_id, 2);
  EXPECT_EQ(f.rgbd.utime, 66667);  // frame 2 at the default 30 Hz
  EXPECT_DOUBLE_EQ(f.rgbd.depth_scale_m, 0.001);
  EXPECT_EQ(f.rgbd.depth(3, 3), 2000);
  EXPECT_EQ(f.rgbd.color(1, 1), (Rgb8{20, 20, 30}));
  EXPECT_DOUBLE_EQ(f.rgbd.camera.fx, 5.0);
  EXPECT_DOUBLE_EQ(f.rgbd.camera.fy, 6.0);
  EXPECT_DOUBLE_EQ(f.rgbd.camera.cx, 4.0);
  EXPECT_DOUBLE_EQ(f.rgbd.camera.cy, 3.0);
  EXPECT_EQ(f.color_stem, "000002");
  ASSERT_TRUE(f.T_W_C.has_value());
  EXPECT_TRUE(f.T_W_C->translation().isApprox(Eigen::Vector3d(0.2, 0.0, 1.0), 1e-12));
  EXPECT_NEAR(Eigen::AngleAxisd(f.T_W_C->linear()).angle(), 20.0 * M_PI / 180.0, 1e-12);
  // The notes say what was detected.
  const std::vector<std::string> notes = reader->notes();
  ASSERT_EQ(notes.size(), 4u);
  EXPECT_NE(notes[0].find("paired by frame number"), std::string::npos);
  EXPECT_NE(notes[2].find("TUM"), std::string::npos);
  EXPECT_NE(notes[3].find("0.001 m per unit (mm), detected"), std::string::npos);
}

TEST(FolderLayout, DetectsTumDepthUnitsAndTakesAGivenScale) {
  test::TempDir dir;
  makeIssueFolder(dir, 2, 10000);  // 10 m in mm: implausible; 2 m at 1/5000 m
  DatasetOptions options;
  EXPECT_DOUBLE_EQ(openDataset(dir.path(), options)->read(0).rgbd.depth_scale_m, 1.0 / 5000.0);
  options.depth_scale_m = 0.0005;
  EXPECT_DOUBLE_EQ(openDataset(dir.path(), options)->read(0).rgbd.depth_scale_m, 0.0005);
  options.depth_scale_m = -1.0;
  EXPECT_THROW(openDataset(dir.path(), options), Error);
}

TEST(FolderLayout, PairsTimestampNamesByTimeAndInterpolatesPoses) {
  test::TempDir dir;
  fs::create_directory(dir.path("color"));
  fs::create_directory(dir.path("depth"));
  // Colour 4 ms after depth; the third depth image has no colour within 20 ms.
  const double depth_t[] = {100.000, 100.050, 100.200};
  const double color_t[] = {100.004, 100.054, 100.300};
  for (int i = 0; i < 3; ++i) {
    char d[64], c[64];
    std::snprintf(d, sizeof(d), "%.6f.png", depth_t[i]);
    std::snprintf(c, sizeof(c), "%.6f.png", color_t[i]);
    writeFrame(dir.path("color/") + c, dir.path("depth/") + d, i, 1500);
  }
  writeText(dir.path("intrinsics.txt"), "5 6 4 3\n");
  writeText(dir.path("groundtruth.txt"),
            "99.99 0 0 0 0 0 0 1\n100.03 0.4 0 0 0 0 0 1\n100.07 0.8 0 0 0 0 0 1\n");
  const auto reader = openDataset(dir.path(), DatasetOptions{});
  ASSERT_EQ(reader->size(), 2u);
  EXPECT_EQ(reader->unmatchedFrames(), 1u);
  const DatasetFrame f = reader->read(1);
  EXPECT_EQ(f.rgbd.utime, 100050000);
  EXPECT_EQ(f.color_stem, "100.054000");
  ASSERT_TRUE(f.T_W_C.has_value());
  EXPECT_NEAR(f.T_W_C->translation().x(), 0.6, 1e-9);  // halfway between 100.03 and 100.07
  EXPECT_NE(reader->notes()[0].find("by timestamp"), std::string::npos);

  // Keyframe poses 200 ms apart (a SLAM system's, Unix times): the frames between take their
  // interpolation; it needed poses 40 ms apart, and every such frame was refused.
  writeText(dir.path("groundtruth.txt"),
            "99.9 0 0 0 0 0 0 1\n100.1 0.4 0 0 0 0 0 1\n100.3 0.8 0 0 0 0 0 1\n");
  const DatasetFrame g = openDataset(dir.path(), DatasetOptions{})->read(1);
  ASSERT_TRUE(g.T_W_C.has_value()) << g.pose_problem;
  EXPECT_NEAR(g.T_W_C->translation().x(), 0.3, 1e-9);  // 100.05: three quarters of the way
  DatasetOptions strict;
  strict.max_pose_gap_s = 0.1;
  const DatasetFrame h = openDataset(dir.path(), strict)->read(1);
  EXPECT_FALSE(h.T_W_C.has_value());
  EXPECT_NE(h.pose_problem.find("nor two at most 0.100000 s apart around it"), std::string::npos)
      << h.pose_problem;
}

TEST(FolderLayout, PairsByPositionAndReadsPoseFolders) {
  test::TempDir dir;
  fs::create_directory(dir.path("rgb"));
  fs::create_directory(dir.path("depth"));
  fs::create_directory(dir.path("pose"));
  // Names that do not pair (colour from another counter), equal counts.
  for (int i = 0; i < 3; ++i) {
    writeFrame(dir.path("rgb/frame" + std::to_string(100 + i) + ".jpg.png"),
               dir.path("depth/" + std::to_string(i) + ".png"), i, 1000);
    writeText(dir.path("pose/" + std::to_string(i) + ".txt"),
              "1 0 0 " + std::to_string(i) + "\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  }
  writeText(dir.path("K.txt"), "5 0 4\n0 6 3\n0 0 1\n");
  const auto reader = openDataset(dir.path(), DatasetOptions{});
  ASSERT_EQ(reader->size(), 3u);
  const DatasetFrame f = reader->read(2);
  EXPECT_EQ(f.color_stem, "frame102.jpg");
  EXPECT_EQ(f.rgbd.color(0, 0), (Rgb8{20, 20, 30}));
  ASSERT_TRUE(f.T_W_C.has_value());
  EXPECT_DOUBLE_EQ(f.T_W_C->translation().x(), 2.0);
  EXPECT_NE(reader->notes()[0].find("by position"), std::string::npos);

  // A missing pose file is that frame's problem, not the sequence's.
  fs::remove(dir.path("pose/1.txt"));
  const DatasetFrame g = openDataset(dir.path(), DatasetOptions{})->read(1);
  EXPECT_FALSE(g.T_W_C.has_value());
  EXPECT_NE(g.pose_problem.find("no pose file for depth image 1.png"), std::string::npos);
}

// A TUM file paired by order keeps its clock: frames of a 10 Hz recording were stamped at
// --rate's 30 Hz, and a trajectory judged against the file matched a third of them.
TEST(FolderLayout, PosesPairedByOrderGiveTheFramesTheirTimes) {
  test::TempDir dir;
  makeIssueFolder(dir, 3);
  std::ofstream(dir.path("gt_pose.txt"))
      << "1700000000.0 0 0 1 0 0 0 1\n1700000000.1 0.1 0 1 0 0 0 1\n"
      << "1700000000.25 0.2 0 1 0 0 0 1\n";
  auto reader = openDataset(dir.path(), DatasetOptions{});
  EXPECT_EQ(reader->read(0).rgbd.utime, 1700000000000000);
  EXPECT_EQ(reader->read(1).rgbd.utime, 1700000000100000);
  EXPECT_EQ(reader->read(2).rgbd.utime, 1700000000250000);
  EXPECT_NE(reader->notes()[2].find("by order (one pose per frame), frame times from its time "
                                    "column"),
            std::string::npos)
      << reader->notes()[2];
  // Times that do not increase say nothing of the frames: --rate's clock.
  std::ofstream(dir.path("gt_pose.txt")) << "5.0 0 0 1 0 0 0 1\n5.0 0.1 0 1 0 0 0 1\n"
                                         << "4.0 0.2 0 1 0 0 0 1\n";
  DatasetOptions at_10_hz;
  at_10_hz.frame_rate_hz = 10.0;
  reader = openDataset(dir.path(), at_10_hz);
  EXPECT_EQ(reader->read(2).rgbd.utime, 200000);
  EXPECT_EQ(reader->notes()[2].find("frame times"), std::string::npos) << reader->notes()[2];
}

// A 16:9 colour image resized onto 4:3 depth was stretched without a word.
TEST(FolderLayout, ColourOfAnotherShapeIsResizedWithAWarning) {
  test::TempDir dir;
  fs::create_directory(dir.path("rgb"));
  fs::create_directory(dir.path("depth"));
  writeFrame(dir.path("rgb/0.png"), dir.path("depth/0.png"), 0, 1000, 16, 9);
  writeText(dir.path("K.txt"), "5 0 4\n0 6 3\n0 0 1\n");
  writeText(dir.path("poses.txt"), "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  const auto reader = openDataset(dir.path(), DatasetOptions{});
  std::string notes;
  for (const std::string& note : reader->notes()) notes += note + "\n";
  EXPECT_NE(notes.find("colour 16x9 (resized to the depth size); warning: colour and depth differ "
                       "in shape (16:9 against 8:6)"),
            std::string::npos)
      << notes;
  EXPECT_EQ(reader->read(0).rgbd.color.width(), 8);
}

TEST(FolderLayout, ColourNumberedFromAnotherStartIsNamed) {
  // Colour 1..4, depth 0..3: paired by number, each colour image would come from the next
  // frame. The import says so, and a pose count that no longer fits names the left-out frame.
  test::TempDir dir;
  fs::create_directory(dir.path("rgb"));
  fs::create_directory(dir.path("depth"));
  for (int i = 0; i < 4; ++i) {
    writeFrame(dir.path("rgb/" + std::to_string(i + 1) + ".png"),
               dir.path("depth/" + std::to_string(i) + ".png"), i, 1000);
  }
  writeText(dir.path("K.txt"), "5 0 4\n0 6 3\n0 0 1\n");
  const auto reader = openDataset(dir.path(), DatasetOptions{});
  EXPECT_EQ(reader->size(), 3u);
  EXPECT_EQ(reader->unmatchedFrames(), 1u);
  EXPECT_EQ(reader->unmatchedWhat(),
            "depth images without a colour image of the same name (first: depth/0.png)");
  EXPECT_NE(reader->notes()[0].find("WARNING: the colour images are numbered 1-4 and the depth "
                                    "images 0-3: if they are the same frames counted from "
                                    "another start, renumber one folder"),
            std::string::npos)
      << reader->notes()[0];
  writeText(dir.path("traj.txt"),
            "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n1 0 0 2 0 1 0 0 0 0 1 0\n"
            "1 0 0 3 0 1 0 0 0 0 1 0\n");
  DatasetOptions options;
  options.poses_path = dir.path("traj.txt");
  try {
    openDataset(dir.path(), options);
    FAIL() << "4 poses were taken for 3 frames";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("for 3 frames: a pose per frame needed (1 depth images "
                                         "were left out for want of a colour image, first "
                                         "depth/0.png)"),
              std::string::npos)
        << e.what();
  }
}

TEST(FolderLayout, MatrixPerLinePosesGivenOnTheCommandLine) {
  test::TempDir dir;
  makeIssueFolder(dir, 2);
  // KITTI-style 3x4 rows, one per frame, in a file named by the user.
  writeText(dir.path("traj_est.txt"), "1 0 0 5 0 1 0 0 0 0 1 0\n1 0 0 6 0 1 0 0 0 0 1 0\n");
  DatasetOptions options;
  options.poses_path = dir.path("traj_est.txt");
  const auto reader = openDataset(dir.path(), options);
  EXPECT_DOUBLE_EQ(reader->read(1).T_W_C->translation().x(), 6.0);
  // One pose too few: the error names the file and both counts.
  writeText(dir.path("traj_est.txt"), "1 0 0 5 0 1 0 0 0 0 1 0\n");
  try {
    openDataset(dir.path(), options);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("traj_est.txt: 1 poses (matrix per line) for 2 frames"),
              std::string::npos)
        << e.what();
  }
}

TEST(FolderLayout, ResizesColourOfAnotherResolution) {
  test::TempDir dir;
  makeIssueFolder(dir, 1);
  writeFrame(dir.path("rgb/000000.png"), dir.path("depth/000000.png"), 3, 2000, 16, 12);
  const DatasetFrame f = openDataset(dir.path(), DatasetOptions{})->read(0);
  EXPECT_EQ(f.rgbd.color.width(), 8);
  EXPECT_EQ(f.color_source_width, 16);
  EXPECT_EQ(f.rgbd.color(4, 4), (Rgb8{30, 20, 30}));
  ASSERT_FALSE(f.color_map_u.empty());
  EXPECT_FLOAT_EQ(f.color_map_u(0, 0), 0.5f);  // pixel centre 0.5 * 2 - 0.5
}

// The intrinsics of the colour camera given for a depth image of half its size: the principal
// point sits at the colour image's centre and is scaled to the depth image.
TEST(FolderLayout, ScalesTheColourCamerasIntrinsicsToTheDepthImage) {
  test::TempDir dir;
  makeIssueFolder(dir, 1);
  writeFrame(dir.path("rgb/000000.png"), dir.path("depth/000000.png"), 0, 2000, 16, 12);
  writeText(dir.path("intrinsic.txt"), "10 0 7.5\n0 12 5.5\n0 0 1\n");
  const auto reader = openDataset(dir.path(), DatasetOptions{});
  const PinholeCamera camera = reader->read(0).rgbd.camera;
  EXPECT_DOUBLE_EQ(camera.fx, 5.0);
  EXPECT_DOUBLE_EQ(camera.fy, 6.0);
  EXPECT_DOUBLE_EQ(camera.cx, 3.5);  // pixel centres: (7.5 + 0.5) / 2 - 0.5
  EXPECT_DOUBLE_EQ(camera.cy, 2.5);
  bool said = false;
  for (const std::string& note : reader->notes()) {
    said |= note.find(
                "the colour camera's (principal point at the colour image's centre), "
                "scaled to the depth size: fx 5, fy 6, cx 3.5, cy 2.5") != std::string::npos;
  }
  EXPECT_TRUE(said);
}

// A principal point found in the folder that fits neither image is an error naming the file, not
// a map shifted by half an image; one that fits the depth image is taken as given.
TEST(FolderLayout, RefusesIntrinsicsThatFitNeitherImage) {
  test::TempDir dir;
  makeIssueFolder(dir, 1);
  writeText(dir.path("intrinsic.txt"), "5 0 7.9\n0 6 3\n0 0 1\n");
  test::expectError([&] { openDataset(dir.path(), DatasetOptions{}); },
                    {"intrinsic.txt: principal point (7.9, 3) lies outside the middle half of "
                     "the 8x6 depth image; give the depth camera's intrinsics"});
  // Given on the command line, the same principal point is the user's word (a cropped sensor).
  DatasetOptions given;
  given.intrinsics = Eigen::Vector4d(5, 6, 7.9, 3);
  EXPECT_DOUBLE_EQ(openDataset(dir.path(), given)->read(0).rgbd.camera.cx, 7.9);
  writeText(dir.path("intrinsic.txt"), "5 0 5.9\n0 6 1.6\n0 0 1\n");
  EXPECT_DOUBLE_EQ(openDataset(dir.path(), DatasetOptions{})->read(0).rgbd.camera.cx, 5.9);
}

TEST(FolderLayout, AutoDetectionListsEveryLayoutTried) {
  test::TempDir dir;
  fs::create_directory(dir.path("depth"));
  try {
    openDataset(dir.path(), DatasetOptions{});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string what = e.what();
    for (const char* expected :
         {"no known dataset layout", "tum: no depth.txt", "scannet: no color/ folder",
          "7scenes: no frame-XXXXXX.depth.png files", "folder: no colour folder"}) {
      EXPECT_NE(what.find(expected), std::string::npos) << what;
    }
  }
}

TEST(FolderLayout, MissingIntrinsicsNamesTheFilesLookedFor) {
  test::TempDir dir;
  makeIssueFolder(dir, 1);
  fs::remove(dir.path("intrinsic.txt"));
  try {
    openDataset(dir.path(), DatasetOptions{});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no intrinsics file (looked for intrinsic.txt"),
              std::string::npos)
        << e.what();
  }
  DatasetOptions options;
  options.intrinsics_file = dir.path("K.txt");
  writeText(options.intrinsics_file, "7 8 4 3");
  EXPECT_DOUBLE_EQ(openDataset(dir.path(), options)->read(0).rgbd.camera.fy, 8.0);
}

TEST(IntrinsicsFile, ReadsTheThreeFormsAndRefusesOthers) {
  test::TempDir dir;
  const std::string path = dir.path("k.txt");
  writeText(path, "# K\n500 0 320\n0 510 240\n0 0 1\n");
  EXPECT_TRUE(readIntrinsicsFile(path).isApprox(Eigen::Vector4d(500, 510, 320, 240)));
  writeText(path, "500 0 320 0\n0 510 240 0\n0 0 1 0\n0 0 0 1\n");
  EXPECT_TRUE(readIntrinsicsFile(path).isApprox(Eigen::Vector4d(500, 510, 320, 240)));
  writeText(path, "500 510 320 240\n");
  EXPECT_TRUE(readIntrinsicsFile(path).isApprox(Eigen::Vector4d(500, 510, 320, 240)));
  writeText(path, "500 510 320 240 7\n");
  EXPECT_THROW(readIntrinsicsFile(path), Error);
  writeText(path, "500 0 320\n0 510 240\n0 1 1\n");  // not a pinhole K
  EXPECT_THROW(readIntrinsicsFile(path), Error);
  writeText(path, "-500 510 320 240\n");
  EXPECT_THROW(readIntrinsicsFile(path), Error);
}

// Exporters name frames by Unix time in ms or ns as often as in seconds; read as seconds, a
// name in ms put frames 33 s apart in the year 43000 and one in ns overflowed the utime.
TEST(FolderLayout, ReadsTimestampNamesInMillisecondsAndNanoseconds) {
  for (const double unit : {1e-3, 1e-9}) {
    test::TempDir dir;
    fs::create_directory(dir.path("rgb"));
    fs::create_directory(dir.path("depth"));
    for (int i = 0; i < 3; ++i) {
      const long long ms = 1305031102175LL + 33 * i;
      const std::string name =
          (unit == 1e-3 ? std::to_string(ms) : std::to_string(ms) + "000000") + ".png";
      writeFrame(dir.path("rgb/") + name, dir.path("depth/") + name, i, 1500);
    }
    writeText(dir.path("intrinsics.txt"), "5 6 4 3\n");
    // Poses with a time column in nanoseconds, 1 m apart along x, 100 ms apart in time.
    writeText(dir.path("groundtruth.txt"),
              "1305031102100000000 0 0 0 0 0 0 1\n1305031102200000000 1 0 0 0 0 0 1\n"
              "1305031102300000000 2 0 0 0 0 0 1\n");
    DatasetOptions options;
    options.tum_max_dt_s = 0.06;
    const auto reader = openDataset(dir.path(), options);
    ASSERT_EQ(reader->size(), 3u);
    const DatasetFrame f = reader->read(1);
    EXPECT_EQ(f.rgbd.utime, 1305031102208000);
    ASSERT_TRUE(f.T_W_C.has_value()) << f.pose_problem;
    EXPECT_NEAR(f.T_W_C->translation().x(), 1.08, 1e-5);  // 108 ms after the pose at x = 0
    EXPECT_NE(reader->notes()[0].find(unit == 1e-3 ? "timestamps in milliseconds"
                                                   : "timestamps in nanoseconds"),
              std::string::npos)
        << reader->notes()[0];
  }
}

// The unit decided on the first image alone read a TUM sequence (1/5000 m) that starts facing
// a wall 1.2 m away as millimetres; the images after it say otherwise.
TEST(FolderLayout, DetectsTheDepthUnitFromImagesAcrossTheSequence) {
  test::TempDir dir;
  makeIssueFolder(dir, 6, 6000);  // 6 m in mm or 1.2 m in TUM units: either would do
  for (int i = 1; i < 6; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    writeFrame(dir.path("rgb/") + name, dir.path("depth/") + name, i, 17500);  // 3.5 m in TUM
  }
  const auto reader = openDataset(dir.path(), DatasetOptions{});
  EXPECT_DOUBLE_EQ(reader->read(0).rgbd.depth_scale_m, 1.0 / 5000.0);
  EXPECT_NE(reader->notes()[3].find("detected from 6 images"), std::string::npos)
      << reader->notes()[3];

  // Every image at 5 m in mm: taken as mm (a hall), with a warning naming the other reading.
  test::TempDir far;
  makeIssueFolder(far, 2, 5000);
  const auto far_reader = openDataset(far.path(), DatasetOptions{});
  EXPECT_DOUBLE_EQ(far_reader->read(0).rgbd.depth_scale_m, 0.001);
  EXPECT_NE(far_reader->notes()[3].find("WARNING"), std::string::npos);
  EXPECT_NE(far_reader->notes()[3].find("--depth-scale 0.0002"), std::string::npos);
}

TEST(PoseList, DetectsFormatsAndKeepsBadPosesAsProblems) {
  test::TempDir dir;
  const std::string path = dir.path("poses.txt");
  writeText(path, "1 0 0 0\n0 1 0 0\n0 0 1 2\n0 0 0 1\n2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  PoseList list = readPoseList(path, 1e-3);
  EXPECT_EQ(list.format, PoseList::Format::kStacked);
  ASSERT_EQ(list.poses.size(), 2u);
  ASSERT_TRUE(list.poses[0].has_value());
  EXPECT_DOUBLE_EQ(list.poses[0]->translation().z(), 2.0);
  EXPECT_FALSE(list.poses[1].has_value());  // scaled rotation
  EXPECT_NE(list.problems[1].find("poses.txt:5: invalid pose"), std::string::npos);

  writeText(path, "0.5 1 2 3 0 0 0 1\n0.6 1 2 3 0 0 0 2\n");
  list = readPoseList(path, 1e-3);
  EXPECT_EQ(list.format, PoseList::Format::kTum);
  EXPECT_DOUBLE_EQ(list.times_s[1], 0.6);
  EXPECT_TRUE(list.poses[0].has_value());
  EXPECT_FALSE(list.poses[1].has_value());  // quaternion of norm 2

  writeText(path, "0.5 1 2 3 0 0 0 1\n0.6 1 2 3 0 0 1\n");
  try {
    readPoseList(path, 1e-3);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("poses.txt:2: 7 numbers where line 1 has 8"),
              std::string::npos)
        << e.what();
  }
  writeText(path, "1305031102100000 1 2 3 0 0 0 1\n1305031102200000 1 2 3 0 0 0 1\n");
  list = readPoseList(path, 1e-3);
  EXPECT_DOUBLE_EQ(list.times_s[1], 1305031102.2);  // microseconds read as such
  EXPECT_EQ(list.time_unit, "microseconds");

  writeText(path, "1 2 3 4 5\n");
  EXPECT_THROW(readPoseList(path, 1e-3), Error);
  writeText(path, "");
  EXPECT_THROW(readPoseList(path, 1e-3), Error);
}

// Redwood's .log (also Augmented ICL-NUIM's *-traj.txt and Open3D's trajectories): a line of
// frame ids and count over each camera-to-world matrix.
TEST(PoseList, ReadsTheLogFormatOfRedwoodAndOpen3D) {
  test::TempDir dir;
  const std::string path = dir.path("livingroom1-traj.txt");
  writeText(path,
            "0 0 2\n1 0 0 0.5\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"
            "1 1 2\n0 -1 0 1\n1 0 0 2\n0 0 1 3\n0 0 0 1\n");
  const PoseList list = readPoseList(path, 1e-3);
  EXPECT_EQ(list.format, PoseList::Format::kLog);
  EXPECT_STREQ(poseListFormatName(list.format), ".log");
  ASSERT_EQ(list.poses.size(), 2u);
  ASSERT_TRUE(list.poses[0] && list.poses[1]);
  EXPECT_DOUBLE_EQ(list.poses[0]->translation().x(), 0.5);
  EXPECT_DOUBLE_EQ(list.poses[1]->translation().z(), 3.0);
  // The camera's x axis points along world y.
  EXPECT_TRUE(list.poses[1]->linear().col(0).isApprox(Eigen::Vector3d(0, 1, 0)));
  EXPECT_TRUE(list.times_s.empty());

  writeText(path, "0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n");
  test::expectError([&] { readPoseList(path, 1e-3); },
                    {"4 lines, not a whole number of .log entries"});
  writeText(path, "0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0 7\n0 0 0 1\n");
  test::expectError([&] { readPoseList(path, 1e-3); },
                    {"livingroom1-traj.txt:4: 5 numbers where a .log entry has 4"});
}

}  // namespace
}  // namespace panmap
