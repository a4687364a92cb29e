#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "panmap/core/error.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/text_files.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;

TEST(SevenScenes, ReadsTheRealSequence) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  const auto reader = openDataset(test::dataDir("7scenes-200"), DatasetOptions{});
  EXPECT_EQ(reader->layoutName(), "7scenes");
  ASSERT_EQ(reader->size(), 200u);
  const DatasetFrame f = reader->read(1);
  EXPECT_EQ(f.rgbd.frame_id, 3);
  EXPECT_EQ(f.rgbd.utime, 100000);  // frame 3 at 30 Hz
  EXPECT_DOUBLE_EQ(f.rgbd.camera.fx, 585.0);
  EXPECT_DOUBLE_EQ(f.rgbd.camera.cy, 240.0);
  EXPECT_EQ(f.rgbd.camera.width, 640);
  EXPECT_EQ(f.rgbd.color.height(), 480);
  EXPECT_EQ(f.color_stem, "frame-000003.color");
  EXPECT_FALSE(f.color_jpeg.empty());  // the JPEG travels unchanged
  ASSERT_TRUE(f.T_W_C.has_value());
  const Eigen::MatrixXd file =
      readMatrixFile(test::dataDir("7scenes-200/frame-000003.pose.txt"), 4, 4);
  EXPECT_LT((f.T_W_C->matrix() - file).cwiseAbs().maxCoeff(), 5e-4);
  EXPECT_EQ(f.T_W_C->translation(), Eigen::Vector3d(file.topRightCorner<3, 1>()));
  const cv::Mat png =
      cv::imread(test::dataDir("7scenes-200/frame-000003.depth.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(png.type(), CV_16UC1);
  EXPECT_EQ(std::memcmp(png.data, f.rgbd.depth.data(), f.rgbd.depth.size() * 2), 0);
}

// A 7-Scenes folder of two frames linked from the real data, for breaking one file at a time.
class SevenScenesBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    PANMAP_REQUIRE_DATA("7scenes-200");
    for (const char* n : {"000000", "000003"}) {
      for (const char* kind : {".color.jpg", ".depth.png", ".pose.txt"}) {
        const std::string name = std::string("frame-") + n + kind;
        fs::create_symlink(test::dataDir("7scenes-200/" + name), dir_.path(name));
      }
    }
    fs::copy_file(test::dataDir("7scenes-200/camera-intrinsics.txt"),
                  dir_.path("camera-intrinsics.txt"));
  }

  // The error of reading every frame, "" if none.
  std::string readAllError() {
    try {
      const auto reader = openDataset(dir_.path(), DatasetOptions{});
      for (size_t i = 0; i < reader->size(); ++i) {
        const DatasetFrame f = reader->read(i);
        if (!f.T_W_C) return f.pose_problem;
      }
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }

  void replace(const std::string& name, const std::vector<uint8_t>& bytes) {
    fs::remove(dir_.path(name));
    writeFileBytes(dir_.path(name), bytes);
  }

  test::TempDir dir_;
};

TEST_F(SevenScenesBadInput, IntactCopyReads) { EXPECT_EQ(readAllError(), ""); }

TEST_F(SevenScenesBadInput, MissingFolder) {
  try {
    openDataset(dir_.path("nope"), DatasetOptions{});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir_.path("nope")), std::string::npos);
  }
}

TEST_F(SevenScenesBadInput, MissingIntrinsics) {
  fs::remove(dir_.path("camera-intrinsics.txt"));
  const std::string error = readAllError();
  EXPECT_NE(error.find("camera-intrinsics.txt"), std::string::npos) << error;
  DatasetOptions options;
  options.intrinsics = Eigen::Vector4d(585, 585, 320, 240);  // the documented way out
  EXPECT_EQ(openDataset(dir_.path(), options)->size(), 2u);
}

TEST_F(SevenScenesBadInput, DepthOfTheWrongSize) {
  replace("frame-000003.depth.png", encodeDepthPng(DepthImage(320, 240, 1000)));
  const std::string error = readAllError();
  EXPECT_NE(error.find("frame-000003.depth.png"), std::string::npos) << error;
  EXPECT_NE(error.find("320x240"), std::string::npos) << error;
}

// Images resized to 320x240 with the 640x480 intrinsics left beside them: the principal point
// sits in the image's corner and every point would be shifted by half an image.
TEST_F(SevenScenesBadInput, ResizedImagesWithTheOriginalIntrinsicsAreNamed) {
  test::TempDir small;
  writeFileBytes(small.path("frame-000000.depth.png"), encodeDepthPng(DepthImage(320, 240, 1000)));
  fs::copy_file(dir_.path("camera-intrinsics.txt"), small.path("camera-intrinsics.txt"));
  try {
    openDataset(small.path(), DatasetOptions{});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string error = e.what();
    EXPECT_NE(error.find("camera-intrinsics.txt: principal point (320, 240)"), std::string::npos)
        << error;
    EXPECT_NE(error.find("those of a 640x480 image"), std::string::npos) << error;
    EXPECT_NE(error.find("--intrinsics 292.5,292.5,159.75,119.75"), std::string::npos) << error;
  }
  DatasetOptions options;
  options.intrinsics = Eigen::Vector4d(292.5, 292.5, 159.75, 119.75);
  EXPECT_EQ(openDataset(small.path(), options)->size(), 1u);
}

// A frame whose depth image is missing was left out of the import without a word.
TEST_F(SevenScenesBadInput, AColourImageWithoutDepthIsCounted) {
  fs::remove(dir_.path("frame-000003.depth.png"));
  const auto reader = openDataset(dir_.path(), DatasetOptions{});
  EXPECT_EQ(reader->size(), 1u);
  EXPECT_EQ(reader->unmatchedFrames(), 1u);
  EXPECT_EQ(reader->unmatchedWhat(),
            "colour images without a depth image (first: frame-000003.color.jpg)");
}

TEST_F(SevenScenesBadInput, TruncatedJpeg) {
  auto bytes = readFileBytes(test::dataDir("7scenes-200/frame-000003.color.jpg"));
  bytes.resize(bytes.size() * 2 / 3);
  replace("frame-000003.color.jpg", bytes);
  const std::string error = readAllError();
  EXPECT_NE(error.find("frame-000003.color.jpg"), std::string::npos) << error;
  EXPECT_NE(error.find("truncated"), std::string::npos) << error;
}

TEST_F(SevenScenesBadInput, NanPose) {
  fs::remove(dir_.path("frame-000003.pose.txt"));
  std::ofstream(dir_.path("frame-000003.pose.txt")) << "1 0 0 nan\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
  const std::string error = readAllError();
  EXPECT_NE(error.find("frame-000003.pose.txt"), std::string::npos) << error;
  EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
}

TEST_F(SevenScenesBadInput, NoFramesAtAll) {
  test::TempDir empty;
  try {
    openDataset(empty.path(), DatasetOptions{});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no frame-XXXXXX.depth.png"), std::string::npos);
  }
}

}  // namespace
}  // namespace panmap
