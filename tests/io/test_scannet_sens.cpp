// ScanNet .sens recordings: read in place frame by frame as their SensReader export would be.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/scannet_sens.h"
#include "scannet_sens_fixture.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;
using test::expectError;

// 4x3 depth, 8x6 colour (raw RGB), depth intrinsics fx = fy = 2, cx = 1.5, cy = 1; colour
// intrinsics twice those (the same field of view at twice the pixels).
ScanNetSensHeader tinyHeader() {
  ScanNetSensHeader h;
  h.sensor_name = "TinySensor";
  h.intrinsic_depth(0, 0) = 2.0f;
  h.intrinsic_depth(1, 1) = 2.0f;
  h.intrinsic_depth(0, 2) = 1.5f;
  h.intrinsic_depth(1, 2) = 1.0f;
  h.intrinsic_color = h.intrinsic_depth;
  h.intrinsic_color.topRows(2) *= 2.0f;
  h.color_compression = static_cast<int32_t>(SensColorCompression::kRaw);
  h.depth_compression = static_cast<int32_t>(SensDepthCompression::kZlib);
  h.color_width = 8;
  h.color_height = 6;
  h.depth_width = 4;
  h.depth_height = 3;
  h.depth_shift = 500.0f;
  return h;
}

DepthImage tinyDepth(uint16_t first) {
  DepthImage depth(4, 3);
  for (size_t i = 0; i < depth.size(); ++i) depth.data()[i] = static_cast<uint16_t>(first + 7 * i);
  return depth;
}

// Frame 0 at the origin, frame 1 lost (-inf, as ScanNet writes it), frame 2 moved 0.5 m in x.
std::vector<ScanNetSensFrame> tinyFrames() {
  std::vector<ScanNetSensFrame> frames(3);
  for (size_t i = 0; i < frames.size(); ++i) {
    frames[i].depth = compressSensDepth(tinyDepth(static_cast<uint16_t>(1000 * (i + 1))));
    frames[i].color.assign(8 * 6 * 3, static_cast<uint8_t>(40 * (i + 1)));
    frames[i].timestamp_depth = 1000 + 33333 * i;
  }
  frames[1].camera_to_world.setConstant(-std::numeric_limits<float>::infinity());
  frames[2].camera_to_world(0, 3) = 0.5f;
  return frames;
}

std::string writeTiny(const test::TempDir& dir, const std::string& name = "scan.sens") {
  writeScanNetSens(dir.path(name), tinyHeader(), tinyFrames());
  return dir.path(name);
}

TEST(ScanNetSens, ReadsExactValuesOfATinyRecording) {
  test::TempDir dir;
  const std::string path = writeTiny(dir);
  const auto reader = openDataset(path, DatasetOptions{});
  EXPECT_EQ(reader->layoutName(), "scannet-sens");
  ASSERT_EQ(reader->size(), 3u);
  EXPECT_TRUE(reader->invalidPosesExpected());

  const DatasetFrame f0 = reader->read(0);
  EXPECT_EQ(f0.rgbd.depth.width(), 4);
  EXPECT_EQ(f0.rgbd.depth.height(), 3);
  for (size_t i = 0; i < 12; ++i) EXPECT_EQ(f0.rgbd.depth.data()[i], 1000 + 7 * i);
  EXPECT_DOUBLE_EQ(f0.rgbd.depth_scale_m, 1.0 / 500.0);
  EXPECT_DOUBLE_EQ(f0.rgbd.camera.fx, 2.0);
  EXPECT_DOUBLE_EQ(f0.rgbd.camera.cx, 1.5);
  EXPECT_EQ(f0.rgbd.camera.width, 4);
  EXPECT_EQ(f0.rgbd.utime, 0);
  EXPECT_EQ(f0.color_stem, "0");  // the name SensReader's export gives colour (and masks)
  EXPECT_EQ(f0.color_source_width, 8);
  EXPECT_EQ(f0.color_source_height, 6);
  ASSERT_TRUE(f0.T_W_C.has_value());
  EXPECT_TRUE(f0.T_W_C->isApprox(Eigen::Isometry3d::Identity()));
  // Identity rig extrinsics, colour intrinsics twice the depth's: depth pixel (u, v) sees
  // colour pixel (4 (u - 1.5) / 2 + 3, 4 (v - 1) / 2 + 2) = (2u, 2v).
  EXPECT_FLOAT_EQ(f0.color_map_u(3, 2), 6.0f);
  EXPECT_FLOAT_EQ(f0.color_map_v(3, 2), 4.0f);
  EXPECT_EQ(f0.rgbd.color(3, 2), (Rgb8{40, 40, 40}));

  const DatasetFrame f1 = reader->read(1);
  EXPECT_FALSE(f1.T_W_C.has_value());
  EXPECT_NE(f1.pose_problem.find(path + " frame 1: invalid pose"), std::string::npos)
      << f1.pose_problem;
  EXPECT_EQ(f1.rgbd.utime, 33333);  // 30 Hz, as the export's frame numbers

  // pose() gives what read() gives, without the images.
  for (size_t i = 0; i < 3; ++i) {
    const DatasetPose p = reader->pose(i);
    const DatasetFrame f = reader->read(i);
    EXPECT_EQ(p.utime, f.rgbd.utime);
    EXPECT_EQ(p.frame_id, f.rgbd.frame_id);
    EXPECT_EQ(p.T_W_C.has_value(), f.T_W_C.has_value());
    if (p.T_W_C) EXPECT_TRUE(p.T_W_C->isApprox(*f.T_W_C, 0.0));
    EXPECT_EQ(p.problem, f.pose_problem);
  }
  expectError([&] { reader->pose(3); }, {path + " frame 3", "has 3 frames"});

  const DatasetFrame f2 = reader->read(2);
  ASSERT_TRUE(f2.T_W_C.has_value());
  EXPECT_DOUBLE_EQ(f2.T_W_C->translation().x(), 0.5);
  EXPECT_EQ(f2.rgbd.depth(0, 0), 3000);
  EXPECT_EQ(f2.rgbd.color(0, 0), (Rgb8{120, 120, 120}));
}

// A scan's calibration comes from its own metadata (<name>.txt beside <name>.sens), never from
// another scan's lying in the same folder.
TEST(ScanNetSens, ColourIsRegisteredWithItsOwnScansMetadata) {
  test::TempDir dir;
  const std::string path = writeTiny(dir);
  const std::string meta =
      "colorWidth = 8\ncolorHeight = 6\ndepthWidth = 4\ndepthHeight = 3\n"
      "colorToDepthExtrinsics = 1 0 0 -0.5 0 1 0 0 0 0 1 0 0 0 0 1\n";
  std::ofstream(dir.path("another_scan.txt")) << meta;
  const DatasetFrame rig = openDataset(path, DatasetOptions{})->read(0);
  EXPECT_FLOAT_EQ(rig.color_map_u(3, 2), 6.0f);
  std::ofstream(dir.path("scan.txt")) << meta;
  const auto reader = openDataset(path, DatasetOptions{});
  EXPECT_NE(reader->notes().back().find("colorToDepthExtrinsics of " + dir.path("scan.txt")),
            std::string::npos);
  // p_D = E p_C puts a depth point 0.5 m further along x in the colour camera, so it lands
  // fx_colour * 0.5 / z pixels further along u: frame 0's pixel (3, 2) holds 1000 + 7 * 11
  // units, z = 2.154 m at 500 units per metre.
  const DatasetFrame f = reader->read(0);
  const double z = (1000 + 7 * 11) / 500.0;
  EXPECT_NEAR(f.color_map_u(3, 2), 6.0 + 4.0 * 0.5 / z, 1e-4);
  EXPECT_FLOAT_EQ(f.color_map_v(3, 2), 4.0f);
}

TEST(ScanNetSens, WriterAndReaderAgreeByteForByte) {
  test::TempDir dir;
  const std::string path = writeTiny(dir);
  const ScanNetSensFile file = ScanNetSensFile::open(path);
  const ScanNetSensHeader h = tinyHeader();
  EXPECT_EQ(file.header().sensor_name, "TinySensor");
  EXPECT_EQ(file.header().intrinsic_color, h.intrinsic_color);
  EXPECT_EQ(file.header().depth_shift, 500.0f);
  const std::vector<ScanNetSensFrame> frames = tinyFrames();
  ASSERT_EQ(file.size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    const ScanNetSensFrame read = file.readFrame(i);
    EXPECT_EQ(read.color, frames[i].color);
    EXPECT_EQ(read.depth, frames[i].depth);
    EXPECT_EQ(read.timestamp_depth, frames[i].timestamp_depth);
    EXPECT_EQ(read.camera_to_world, frames[i].camera_to_world);  // -inf == -inf too
  }
  // 4 + 8 + 10 name + 4 x 64 matrices + 2 x 4 compression + 4 x 4 sizes + 4 shift + 8 count,
  // then per frame 96 bytes of record and its images.
  uint64_t expected = 4 + 8 + 10 + 256 + 8 + 16 + 4 + 8;
  for (const ScanNetSensFrame& f : frames) expected += 96 + f.color.size() + f.depth.size();
  EXPECT_EQ(fs::file_size(path), expected);
}

// The shared ScanNet fixture written as a .sens reads back as the export itself does.
TEST(ScanNetSens, ReadsAsItsExportDoes) {
  PANMAP_REQUIRE_DATA("scannet-export-3");
  const std::string src = test::dataDir("scannet-export-3");
  test::TempDir dir;
  std::filesystem::create_directory(dir.path("scans"));
  test::writeScanNetExportAsSens(dir.path("scans/scene0707_00.sens"));
  const auto sens = openDataset(dir.path("scans"), DatasetOptions{});  // found in its folder
  const auto exported = openDataset(src, DatasetOptions{});
  EXPECT_EQ(sens->layoutName(), "scannet-sens");
  ASSERT_EQ(sens->size(), exported->size());
  const std::vector<std::string> notes = sens->notes();
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(notes[1].find("colorToDepthExtrinsics of"), std::string::npos) << notes[1];
  for (size_t i = 0; i < sens->size(); ++i) {
    const DatasetFrame a = sens->read(i);
    const DatasetFrame b = exported->read(i);
    EXPECT_EQ(a.rgbd.depth.width(), 640);
    EXPECT_TRUE(std::equal(a.rgbd.depth.data(), a.rgbd.depth.data() + a.rgbd.depth.size(),
                           b.rgbd.depth.data()));
    EXPECT_EQ(a.rgbd.utime, b.rgbd.utime);
    EXPECT_EQ(a.rgbd.frame_id, b.rgbd.frame_id);
    EXPECT_EQ(a.color_stem, b.color_stem);
    EXPECT_EQ(a.rgbd.depth_scale_m, b.rgbd.depth_scale_m);
    // Floats in the file, six decimals in the export's text.
    EXPECT_NEAR(a.rgbd.camera.fx, b.rgbd.camera.fx, 1e-4);
    EXPECT_NEAR(a.rgbd.camera.cy, b.rgbd.camera.cy, 1e-4);
    ASSERT_TRUE(a.T_W_C && b.T_W_C);
    EXPECT_TRUE(a.T_W_C->matrix().isApprox(b.T_W_C->matrix(), 1e-6));
    // The same JPEG through the same registration: colour maps within float rounding of the
    // intrinsics, colours within one grey level.
    EXPECT_NEAR(a.color_map_u(320, 240), b.color_map_u(320, 240), 1e-3);
    int worst = 0;
    for (size_t p = 0; p < a.rgbd.color.size(); ++p) {
      const Rgb8 x = a.rgbd.color.data()[p], y = b.rgbd.color.data()[p];
      worst = std::max({worst, std::abs(x.r - y.r), std::abs(x.g - y.g), std::abs(x.b - y.b)});
    }
    EXPECT_LE(worst, 1) << "frame " << i;
  }
}

// Writes `bytes` over the file from `offset` on (keeping its length).
void overwrite(const std::string& path, uint64_t offset, const std::vector<uint8_t>& bytes) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(static_cast<std::streamoff>(offset));
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

constexpr uint64_t kTinyHeaderBytes = 4 + 8 + 10 + 256 + 8 + 16 + 4 + 8;

TEST(ScanNetSens, BrokenFilesAreNamedInOneLine) {
  test::TempDir dir;
  const std::string path = writeTiny(dir);
  const uint64_t full = fs::file_size(path);

  fs::resize_file(path, full - 5);  // a partial download
  expectError([&] { openDataset(path, DatasetOptions{}); },
              {path, "frame 2 of 3", "ends inside it"});
  fs::resize_file(path, 30);
  expectError([&] { ScanNetSensFile::open(path); }, {path, "file ends inside the"});

  writeTiny(dir);
  overwrite(path, 0, {3, 0, 0, 0});
  expectError([&] { ScanNetSensFile::open(path); }, {path, "version 3"});

  writeTiny(dir);
  overwrite(path, kTinyHeaderBytes - 8, {0, 0, 0, 0, 0, 0, 1, 0});  // 2^48 frames
  expectError([&] { ScanNetSensFile::open(path); }, {path, "cannot hold them"});

  writeTiny(dir);
  overwrite(path, 4, {0, 0, 0, 0, 0, 0, 0, 1});  // a name of 2^56 bytes
  expectError([&] { ScanNetSensFile::open(path); }, {path, "sensor name of"});

  writeTiny(dir);
  overwrite(path, kTinyHeaderBytes + 80, {0, 0, 0, 0, 0, 0, 0, 1});  // frame 0's colour: 2^56 B
  expectError([&] { ScanNetSensFile::open(path); }, {path, "frame 0 of 3", "not a frame record"});
}

TEST(ScanNetSens, BrokenFramesAreNamedAndTheOthersStillRead) {
  test::TempDir dir;
  ScanNetSensHeader h = tinyHeader();
  std::vector<ScanNetSensFrame> frames = tinyFrames();
  frames[0].depth[frames[0].depth.size() / 2] ^= 0xFF;    // corrupt the deflate stream
  frames[1].depth = compressSensDepth(DepthImage(4, 2));  // 8 pixels, not 12
  frames[2].color.resize(10);                             // not 8x6 RGB
  writeScanNetSens(dir.path("a.sens"), h, frames);
  const auto reader = openDataset(dir.path("a.sens"), DatasetOptions{});
  const std::string path = dir.path("a.sens");
  expectError([&] { reader->read(0); }, {path + " frame 0", "depth"});
  expectError([&] { reader->read(1); }, {path + " frame 1", "holds 8 pixels, not 4x3"});
  expectError([&] { reader->read(2); }, {path + " frame 2 colour", "10 bytes, not 8x6 RGB"});
  expectError([&] { reader->read(3); }, {path + " frame 3", "has 3 frames"});

  h.depth_compression = 2;  // occi: not ScanNet's, not read
  writeScanNetSens(dir.path("occi.sens"), h, tinyFrames());
  const auto occi = openDataset(dir.path("occi.sens"), DatasetOptions{});
  expectError([&] { occi->read(0); }, {"depth compression 2 is not read"});
}

TEST(ScanNetSens, FoldersAndFilesAreTold) {
  test::TempDir dir;
  writeTiny(dir, "a.sens");
  writeTiny(dir, "b.sens");
  expectError([&] { openDataset(dir.path(), DatasetOptions{}); },
              {"no known dataset layout", "scannet-sens: 2 *.sens files"});
  EXPECT_EQ(openDataset(dir.path("b.sens"), DatasetOptions{})->size(), 3u);
  std::ofstream(dir.path("poses.txt")) << "1 0 0 0\n";
  expectError([&] { openDataset(dir.path("poses.txt"), DatasetOptions{}); },
              {"a folder or a ScanNet .sens file"});
  DatasetOptions tum;
  tum.layout = DatasetLayout::kTum;
  expectError([&] { openDataset(dir.path("a.sens"), tum); }, {"the tum layout is a folder"});
  EXPECT_EQ(parseDatasetLayout("scannet-sens"), DatasetLayout::kScanNetSens);
  EXPECT_STREQ(datasetLayoutName(DatasetLayout::kScanNetSens), "scannet-sens");
}

TEST(ScanNetSens, TheDepthScaleOptionOverridesTheFile) {
  test::TempDir dir;
  DatasetOptions options;
  options.depth_scale_m = 0.001;
  EXPECT_DOUBLE_EQ(openDataset(writeTiny(dir), options)->read(0).rgbd.depth_scale_m, 0.001);
}

}  // namespace
}  // namespace panmap
