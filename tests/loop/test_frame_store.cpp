// The frame store a loop-closure repair re-integrates from: exact round trips, reopening, and
// what a crash or a damaged file leaves behind.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "panmap/loop/frame_store.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;
using test::expectError;
using test::TempDir;

constexpr int kWidth = 64;
constexpr int kHeight = 48;

PinholeCamera camera() {
  PinholeCamera c;
  c.fx = 585.123456789012;  // digits a decimal round trip at default precision would lose
  c.fy = 584.9876543210987;
  c.cx = 31.7;
  c.cy = 23.3;
  c.width = kWidth;
  c.height = kHeight;
  return c;
}

// A pose whose entries are not short decimals (rotations by non-round angles).
Eigen::Isometry3d pose(double seed) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.3 + seed, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(-0.7 * seed + 0.1, Eigen::Vector3d(1, 2, 3).normalized()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(1.0 / 3.0 + seed, -2.0 / 7.0, 0.1 * seed + 1e-9);
  return T;
}

// Depth over the whole 16-bit range (0 = no measurement, 65535 the largest unit).
DepthImage depth(int seed) {
  DepthImage d(kWidth, kHeight);
  uint32_t x = 12345u + static_cast<uint32_t>(seed);
  for (size_t i = 0; i < d.size(); ++i) {
    x = x * 1664525u + 1013904223u;
    d.data()[i] = static_cast<uint16_t>(x >> 16);
  }
  d(0, 0) = 0;
  d(1, 0) = 65535;
  return d;
}

// Piecewise-constant labels, as association produces, with the values a naive encoding loses.
LabelImage labels(int seed) {
  LabelImage l(kWidth, kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) l(u, v) = 1 + seed + (u / 16) + 4 * (v / 16);
  }
  l(0, 0) = 0;
  l(1, 0) = 65536;                                // above 16 bits
  l(2, 0) = 70001;                                // above 16 bits
  l(3, 0) = (1 << 24) - 1;                        // the largest COCO RGB id
  l(4, 0) = (1 << 24) + 5;                        // needs the high plane
  l(5, 0) = std::numeric_limits<int32_t>::max();  // every bit
  l(6, 0) = -1;                                   // not a super-point id, still lossless
  return l;
}

ColorImage color() {
  ColorImage c(kWidth, kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      c(u, v) = Rgb8{static_cast<uint8_t>(4 * u), static_cast<uint8_t>(5 * v), 128};
    }
  }
  return c;
}

// Bitwise: the store keeps the doubles it was given, not approximations.
void expectSamePose(const Eigen::Isometry3d& actual, const Eigen::Isometry3d& expected) {
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(actual.matrix()(r, c), expected.matrix()(r, c)) << "entry " << r << "," << c;
    }
  }
}

void expectSameCamera(const PinholeCamera& a, const PinholeCamera& b) {
  EXPECT_EQ(a.fx, b.fx);
  EXPECT_EQ(a.fy, b.fy);
  EXPECT_EQ(a.cx, b.cx);
  EXPECT_EQ(a.cy, b.cy);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
}

// Adds frame i (utime 1000 + i) with the images above.
void addFrame(FrameStore* store, int i, const ColorImage* c = nullptr) {
  store->add(1000 + i, pose(0.1 * i), camera(), 0.001, depth(i), labels(i), c);
}

void expectFrame(const StoredFrame& f, int i) {
  EXPECT_EQ(f.rgbd.utime, 1000 + i);
  expectSamePose(f.T_W_C, pose(0.1 * i));
  expectSameCamera(f.rgbd.camera, camera());
  EXPECT_EQ(f.rgbd.depth_scale_m, 0.001);
  EXPECT_TRUE(f.rgbd.depth == depth(i)) << "depth of frame " << i;
  EXPECT_TRUE(f.labels == labels(i)) << "labels of frame " << i;
}

FrameStoreConfig configIn(const TempDir& dir) {
  FrameStoreConfig config;
  config.folder = dir.path("store");
  return config;
}

void flipByte(const std::string& path, size_t offset) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(static_cast<std::streamoff>(offset));
  char c = 0;
  f.read(&c, 1);
  c = static_cast<char>(c ^ 0x5a);
  f.seekp(static_cast<std::streamoff>(offset));
  f.write(&c, 1);
}

TEST(FrameStore, RoundTripIsExact) {
  TempDir dir;
  FrameStore store(configIn(dir));
  addFrame(&store, 0);
  EXPECT_EQ(store.size(), 1u);
  EXPECT_EQ(store.utimes(), std::vector<int64_t>{1000});
  const StoredFrame f = store.load(1000);
  expectFrame(f, 0);
  // A new store writes version 2: one zstd plane per image, whatever its labels.
  EXPECT_EQ(store.version(), 2);
  EXPECT_TRUE(fs::exists(dir.path("store/frames/1000.depth.zst")));
  EXPECT_TRUE(fs::exists(dir.path("store/frames/1000.labels.zst")));
  EXPECT_FALSE(fs::exists(dir.path("store/frames/1000.labels-hi.png")));
  EXPECT_TRUE(f.rgbd.color.empty());  // colour is off by default
  // Bytes on disk are the files plus the index.
  uint64_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir.path("store/frames"))) {
    files += entry.file_size();
  }
  EXPECT_EQ(store.bytesOnDisk(), files + fs::file_size(dir.path("store/index.txt")));
  EXPECT_EQ(store.frameBytes(1000).total(), files);
}

TEST(FrameStore, EveryCompressionLevelRoundTrips) {
  TempDir dir;
  for (int level : {1, 19}) {
    FrameStoreConfig config = configIn(dir);
    config.folder = dir.path("store" + std::to_string(level));
    config.compression_level = level;
    FrameStore store(config);
    store.add(7, pose(0.0), camera(), 0.00025, depth(0), labels(2));
    const StoredFrame f = store.load(7);
    EXPECT_TRUE(f.labels == labels(2));
    EXPECT_TRUE(f.rgbd.depth == depth(0));
    EXPECT_EQ(f.rgbd.depth_scale_m, 0.00025);
  }
}

// tests/fixtures/frame_store_v1 was written by panmap at commit 4b7e4d0 (PNG frames, a second
// PNG for ids above 2^24), two 8x6 frames, the second with a segmentation, then a pose update.
TEST(FrameStore, Version1StoresAreReadAndGrowInTheirOwnFormat) {
  TempDir dir;
  fs::copy(test::fixtureDir("frame_store_v1"), dir.path("store"), fs::copy_options::recursive);
  auto expected_depth = [](int f) {
    DepthImage d(8, 6);
    for (int i = 0; i < 48; ++i) d.data()[i] = static_cast<uint16_t>(1000 + 37 * i + f);
    d.data()[0] = 0;
    d.data()[1] = 65535;
    return d;
  };
  auto expected_labels = [](int f) {
    LabelImage l(8, 6);
    for (int i = 0; i < 48; ++i) l.data()[i] = 1 + f + i / 12;
    l.data()[0] = 0;
    l.data()[1] = (1 << 24) + 5;
    l.data()[2] = std::numeric_limits<int32_t>::max();
    l.data()[3] = -1;
    return l;
  };
  {
    const auto store = FrameStore::open(dir.path("store"));
    EXPECT_TRUE(store->problems().empty());
    EXPECT_EQ(store->version(), 1);
    ASSERT_EQ(store->utimes(), (std::vector<int64_t>{1000000, 1200000}));
    const StoredFrame a = store->load(1000000);
    EXPECT_TRUE(a.rgbd.depth == expected_depth(0));
    EXPECT_TRUE(a.labels == expected_labels(0));
    EXPECT_FALSE(a.has_panoptic);
    EXPECT_EQ(a.T_W_C.translation(), Eigen::Vector3d(0.0, -0.5, 1.125));  // the pose update
    const StoredFrame b = store->load(1200000);
    EXPECT_TRUE(b.labels == expected_labels(1));
    ASSERT_TRUE(b.has_panoptic);
    EXPECT_EQ(b.panoptic.segment_ids(0, 0), 1);
    EXPECT_EQ(b.panoptic.segment_ids(7, 5), (1 << 24) + 2);
    ASSERT_EQ(b.panoptic.segments.size(), 2u);
    EXPECT_EQ(b.panoptic.segments[0].score, 0.75f);
  }
  // Continuing the store adds PNG frames to it, which read back like the old ones.
  FrameStore again(configIn(dir));
  EXPECT_EQ(again.version(), 1);
  LabelImage l = expected_labels(5);
  again.add(1400000, pose(0.2), again.load(1000000).rgbd.camera, 0.001, expected_depth(5), l);
  EXPECT_TRUE(fs::exists(dir.path("store/frames/1400000.depth.png")));
  EXPECT_TRUE(fs::exists(dir.path("store/frames/1400000.labels-hi.png")));
  const auto reopened = FrameStore::open(dir.path("store"));
  EXPECT_TRUE(reopened->problems().empty());
  EXPECT_EQ(reopened->size(), 3u);
  EXPECT_TRUE(reopened->load(1400000).labels == l);
}

TEST(FrameStore, AnIndexOfAnotherVersionIsRefusedByName) {
  TempDir dir;
  fs::create_directories(dir.path("store"));
  std::ofstream(dir.path("store/index.txt")) << "panmap-frame-store 3\n";
  expectError([&] { FrameStore::open(dir.path("store")); },
              {"index.txt", "panmap-frame-store 1", "panmap-frame-store 2"});
}

TEST(FrameStore, ColourIsStoredAsJpegWhenAsked) {
  TempDir dir;
  FrameStoreConfig config = configIn(dir);
  config.store_color = true;
  config.color_quality = 90;
  FrameStore store(config);
  const ColorImage c = color();
  addFrame(&store, 0, &c);
  const StoredFrame f = store.load(1000);
  expectFrame(f, 0);
  ASSERT_EQ(f.rgbd.color.width(), kWidth);
  ASSERT_EQ(f.rgbd.color.height(), kHeight);
  // JPEG is lossy: a smooth gradient comes back within a few levels on average.
  double error = 0.0;
  for (size_t i = 0; i < c.size(); ++i) {
    error += std::abs(f.rgbd.color.data()[i].r - c.data()[i].r) +
             std::abs(f.rgbd.color.data()[i].g - c.data()[i].g) +
             std::abs(f.rgbd.color.data()[i].b - c.data()[i].b);
  }
  EXPECT_LT(error / (3.0 * c.size()), 4.0);
  EXPECT_GT(store.frameBytes(1000).color, 0u);
}

TEST(FrameStore, ColourIsIgnoredWhenOff) {
  TempDir dir;
  FrameStore store(configIn(dir));
  const ColorImage c = color();
  addFrame(&store, 0, &c);
  EXPECT_TRUE(store.load(1000).rgbd.color.empty());
  EXPECT_FALSE(fs::exists(dir.path("store/frames/1000.color.jpg")));
}

TEST(FrameStore, ReopenGivesTheSameFrames) {
  TempDir dir;
  uint64_t bytes = 0;
  {
    FrameStore store(configIn(dir));
    for (int i = 2; i >= 0; --i) addFrame(&store, i);  // out of order: utimes() sorts
    bytes = store.bytesOnDisk();
  }
  const auto store = FrameStore::open(dir.path("store"));
  EXPECT_TRUE(store->problems().empty()) << store->problems().front();
  EXPECT_EQ(store->skipped(), 0u);
  EXPECT_EQ(store->utimes(), (std::vector<int64_t>{1000, 1001, 1002}));
  EXPECT_EQ(store->bytesOnDisk(), bytes);
  for (int i = 0; i < 3; ++i) expectFrame(store->load(1000 + i), i);
  const std::vector<StampedPose> trajectory = store->trajectory();
  ASSERT_EQ(trajectory.size(), 3u);
  EXPECT_EQ(trajectory[1].utime, 1001);
  expectSamePose(trajectory[1].T_W_C, pose(0.1));
  // Constructing a store on a folder that holds one continues it.
  FrameStore again(configIn(dir));
  EXPECT_EQ(again.size(), 3u);
  addFrame(&again, 3);
  EXPECT_EQ(FrameStore::open(dir.path("store"))->size(), 4u);
}

TEST(FrameStore, MissingCutOrCorruptFilesAreNamedAndSkipped) {
  TempDir dir;
  {
    FrameStore store(configIn(dir));
    for (int i = 0; i < 5; ++i) addFrame(&store, i);
  }
  const std::string frames = dir.path("store/frames/");
  fs::remove(frames + "1001.depth.zst");
  fs::resize_file(frames + "1002.labels.zst", fs::file_size(frames + "1002.labels.zst") / 2);
  flipByte(frames + "1003.depth.zst", 100);  // same size, other bytes
  // A file of the wrong frame: same name pattern, another frame's bytes.
  fs::copy_file(frames + "1000.labels.zst", frames + "1004.labels.zst",
                fs::copy_options::overwrite_existing);

  const auto store = FrameStore::open(dir.path("store"));
  EXPECT_EQ(store->utimes(), std::vector<int64_t>{1000});
  EXPECT_EQ(store->skipped(), 4u);
  const std::vector<std::string> problems = store->problems();
  ASSERT_EQ(problems.size(), 4u);
  const auto named = [&](const std::string& a, const std::string& b) {
    for (const std::string& p : problems) {
      EXPECT_EQ(p.find('\n'), std::string::npos);
      if (p.find(a) != std::string::npos && p.find(b) != std::string::npos) return true;
    }
    return false;
  };
  EXPECT_TRUE(named("frame 1001", "1001.depth.zst is missing"));
  EXPECT_TRUE(named("frame 1002", "1002.labels.zst has"));
  EXPECT_TRUE(named("frame 1003", "1003.depth.zst is corrupt"));
  EXPECT_TRUE(named("frame 1004", "1004.labels.zst"));
  expectFrame(store->load(1000), 0);
  expectError([&] { store->load(1003); }, {"1003"});

  // Checking sizes only lets the same-size corruption through to load(), which names the file.
  const auto quick = FrameStore::open(dir.path("store"), FrameStore::Check::kSizes);
  EXPECT_EQ(quick->utimes(), (std::vector<int64_t>{1000, 1003}));
  expectError([&] { quick->load(1003); }, {"frame 1003", "1003.depth.zst", "differs"});
}

TEST(FrameStore, CutLastIndexLineIsDroppedAndTheStoreContinues) {
  TempDir dir;
  std::string index_path = dir.path("store/index.txt");
  {
    FrameStore store(configIn(dir));
    for (int i = 0; i < 3; ++i) addFrame(&store, i);
  }
  // A crash while appending frame 1003's line: its files are whole, its line is not.
  std::string text = test::fileBytes(index_path);
  const size_t last = text.rfind("frame 1002");
  const std::string line = text.substr(last);
  text = text.substr(0, last) + line.substr(0, line.size() / 2);
  std::ofstream(index_path, std::ios::binary | std::ios::trunc) << text;
  {
    const auto store = FrameStore::open(dir.path("store"));
    EXPECT_EQ(store->utimes(), (std::vector<int64_t>{1000, 1001}));
    ASSERT_EQ(store->problems().size(), 1u);
    EXPECT_NE(store->problems()[0].find("cut last line"), std::string::npos);
    EXPECT_EQ(store->skipped(), 0u);  // no frame line was whole: nothing to skip
    addFrame(store.get(), 2);         // the frame comes back on a line of its own
  }
  const auto store = FrameStore::open(dir.path("store"));
  EXPECT_TRUE(store->problems().empty()) << store->problems().front();
  EXPECT_EQ(store->utimes(), (std::vector<int64_t>{1000, 1001, 1002}));
  expectFrame(store->load(1002), 2);
}

TEST(FrameStore, CorruptIndexLineIsNamedAndTheOthersLoad) {
  TempDir dir;
  {
    FrameStore store(configIn(dir));
    for (int i = 0; i < 3; ++i) addFrame(&store, i);
  }
  const std::string index_path = dir.path("store/index.txt");
  std::string text = test::fileBytes(index_path);
  const size_t at = text.find("frame 1001 ") + 11;  // the first digit of fx
  text[at] = text[at] == '5' ? '6' : '5';
  std::ofstream(index_path, std::ios::binary | std::ios::trunc) << text;
  const auto store = FrameStore::open(dir.path("store"));
  EXPECT_EQ(store->utimes(), (std::vector<int64_t>{1000, 1002}));
  ASSERT_EQ(store->problems().size(), 1u);
  EXPECT_NE(store->problems()[0].find("index.txt line 3: corrupt"), std::string::npos)
      << store->problems()[0];
  expectFrame(store->load(1002), 2);
}

TEST(FrameStore, NotAStoreIsRefused) {
  TempDir dir;
  expectError([&] { FrameStore::open(dir.path("nothing")); }, {dir.path("nothing"), "index.txt"});
  fs::create_directories(dir.path("store"));
  std::ofstream(dir.path("store/index.txt")) << "something else\n";
  expectError([&] { FrameStore::open(dir.path("store")); },
              {dir.path("store"), "panmap-frame-store"});
}

TEST(FrameStore, LoadOfAnUnknownUtimeNamesIt) {
  TempDir dir;
  FrameStore store(configIn(dir));
  addFrame(&store, 0);
  expectError([&] { store.load(987654321); }, {"987654321"});
  expectError([&] { store.frameBytes(987654321); }, {"987654321"});
}

TEST(FrameStore, UpdatePosePersistsAcrossReopen) {
  TempDir dir;
  {
    FrameStore store(configIn(dir));
    for (int i = 0; i < 3; ++i) addFrame(&store, i);
    store.updatePose(1001, pose(5.0));
    store.updatePose(1001, pose(7.0));  // the latest wins
    store.updatePose(1002, pose(9.0));
    expectSamePose(store.load(1001).T_W_C, pose(7.0));
    expectError([&] { store.updatePose(55, pose(1.0)); }, {"55", "not stored"});
    Eigen::Isometry3d sheared = pose(1.0);
    sheared.matrix()(0, 1) += 0.1;
    expectError([&] { store.updatePose(1000, sheared); }, {"1000", "pose"});
  }
  const auto store = FrameStore::open(dir.path("store"));
  EXPECT_TRUE(store->problems().empty()) << store->problems().front();
  expectSamePose(store->load(1000).T_W_C, pose(0.0));
  expectSamePose(store->load(1001).T_W_C, pose(7.0));
  expectSamePose(store->load(1002).T_W_C, pose(9.0));
  expectSamePose(store->trajectory()[1].T_W_C, pose(7.0));
  EXPECT_TRUE(store->load(1001).labels == labels(1));
}

TEST(FrameStore, AddRefusesDuplicatesAndBadInputStoringNothing) {
  TempDir dir;
  FrameStore store(configIn(dir));
  addFrame(&store, 0);
  const uint64_t bytes = store.bytesOnDisk();
  expectError([&] { addFrame(&store, 0); }, {"1000", "already stored"});
  expectError([&] { store.add(1, pose(0.0), camera(), 0.001, depth(0), LabelImage(3, 3)); },
              {"frame 1", "label image"});
  expectError([&] { store.add(1, pose(0.0), camera(), 0.001, DepthImage(3, 3), labels(0)); },
              {"frame 1", "depth image"});
  expectError([&] { store.add(1, pose(0.0), camera(), 0.0, depth(0), labels(0)); },
              {"frame 1", "depth_scale_m"});
  Eigen::Isometry3d bad = pose(0.0);
  bad.matrix()(0, 3) = std::numeric_limits<double>::quiet_NaN();
  expectError([&] { store.add(1, bad, camera(), 0.001, depth(0), labels(0)); },
              {"frame 1", "pose"});
  PinholeCamera no_focal = camera();
  no_focal.fx = 0.0;
  expectError([&] { store.add(1, pose(0.0), no_focal, 0.001, depth(0), labels(0)); },
              {"frame 1", "intrinsics"});
  EXPECT_EQ(store.size(), 1u);
  EXPECT_EQ(store.bytesOnDisk(), bytes);
  EXPECT_FALSE(fs::exists(dir.path("store/frames/1.depth.zst")));
}

TEST(FrameStore, ConfigCheckRejectsBadValues) {
  FrameStoreConfig config;
  EXPECT_NO_THROW(config.check());  // empty folder: the store is off, a valid choice
  config.color_quality = 0;
  expectError([&] { config.check(); }, {"color_quality"});
  config.color_quality = 101;
  expectError([&] { config.check(); }, {"color_quality"});
  config.color_quality = 50;
  config.compression_level = 20;
  expectError([&] { config.check(); }, {"compression_level"});
  config.compression_level = 0;
  expectError([&] { config.check(); }, {"compression_level"});
  config.compression_level = 1;
  EXPECT_NO_THROW(config.check());
  config.folder = "a\nb";
  expectError([&] { config.check(); }, {"folder"});
  // A store needs a folder.
  expectError([] { FrameStore store{FrameStoreConfig{}}; }, {"folder", "off"});
  TempDir dir;
  FrameStoreConfig bad = configIn(dir);
  bad.color_quality = -3;
  expectError([&] { FrameStore store(bad); }, {"color_quality"});
}

// A segmentation as a network gives it: ids up to 2^24 and beyond (and -1 on one pixel, which
// no segment names), scores that are not short decimals.
PanopticFrame segmentation() {
  PanopticFrame p;
  p.segment_ids = LabelImage(kWidth, kHeight, 0);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) p.segment_ids(u, v) = u < 20 ? 3 : (v < 10 ? 0 : 70001);
  }
  p.segment_ids(5, 5) = (1 << 24) + 5;
  p.segment_ids(6, 5) = -1;
  p.segments = {{3, 5, 1001, true, 0.123456789f},
                {70001, 1, 2, false, 1.0f},
                {(1 << 24) + 5, 40, 40, true, 1.0f / 3.0f}};
  return p;
}

TEST(FrameStore, PanopticSegmentationsRoundTripExactly) {
  TempDir dir;
  const PanopticFrame p = segmentation();
  {
    FrameStore store(configIn(dir));
    store.add(2000, pose(0.5), camera(), 0.001, depth(3), LabelImage(kWidth, kHeight, 9), nullptr,
              &p);
    addFrame(&store, 0);  // without one
    EXPECT_EQ(store.size(), 2u);
    EXPECT_EQ(store.sizeWithPanoptic(), 1u);
    EXPECT_GT(store.frameBytes(2000).masks, 0u);
    EXPECT_EQ(store.frameBytes(1000).masks, 0u);
  }
  const auto store = FrameStore::open(dir.path("store"));
  EXPECT_TRUE(store->problems().empty());
  EXPECT_EQ(store->sizeWithPanoptic(), 1u);
  const StoredFrame f = store->load(2000);
  ASSERT_TRUE(f.has_panoptic);
  EXPECT_EQ(f.panoptic.utime, 2000);
  EXPECT_TRUE(f.panoptic.segment_ids == p.segment_ids);
  EXPECT_EQ(f.panoptic.segments, p.segments);
  EXPECT_TRUE(fs::exists(dir.path("store/frames/2000.masks.zst")));
  EXPECT_FALSE(fs::exists(dir.path("store/frames/2000.masks-hi.png")));
  const StoredFrame g = store->load(1000);
  EXPECT_FALSE(g.has_panoptic);
  expectFrame(g, 0);
  // A segmentation of another size is refused, storing nothing.
  PanopticFrame small = p;
  small.segment_ids = LabelImage(8, 8, 3);
  expectError(
      [&] {
        store->add(3000, pose(0.1), camera(), 0.001, depth(1), LabelImage(kWidth, kHeight, 1),
                   nullptr, &small);
      },
      {"frame 3000", "panoptic segment image"});
  EXPECT_EQ(store->size(), 2u);
}

TEST(FrameStore, DamagedMasksLeaveTheFrameOutByName) {
  TempDir dir;
  const PanopticFrame p = segmentation();
  {
    FrameStore store(configIn(dir));
    for (int64_t utime : {10, 11}) {
      store.add(utime, pose(0.5), camera(), 0.001, depth(3), LabelImage(kWidth, kHeight, 9),
                nullptr, &p);
    }
  }
  flipByte(dir.path("store/frames/11.segments.txt"), 2);
  const auto store = FrameStore::open(dir.path("store"));
  EXPECT_EQ(store->utimes(), std::vector<int64_t>{10});
  ASSERT_EQ(store->problems().size(), 1u);
  EXPECT_NE(store->problems()[0].find("11.segments.txt is corrupt"), std::string::npos)
      << store->problems()[0];
  EXPECT_TRUE(store->load(10).has_panoptic);
}

// A crash while appending a frame's two lines can cut the second: the frame stays, without
// its segmentation, and a repair re-integrates instead of associating again.
TEST(FrameStore, ACutMasksLineKeepsTheFrameWithoutItsSegmentation) {
  TempDir dir;
  const PanopticFrame p = segmentation();
  {
    FrameStore store(configIn(dir));
    store.add(10, pose(0.5), camera(), 0.001, depth(3), LabelImage(kWidth, kHeight, 9), nullptr,
              &p);
  }
  const std::string index = dir.path("store/index.txt");
  fs::resize_file(index, fs::file_size(index) - 5);
  const auto store = FrameStore::open(dir.path("store"));
  EXPECT_EQ(store->utimes(), std::vector<int64_t>{10});
  EXPECT_EQ(store->sizeWithPanoptic(), 0u);
  EXPECT_FALSE(store->load(10).has_panoptic);
  ASSERT_EQ(store->problems().size(), 1u);
  EXPECT_NE(store->problems()[0].find("cut last line"), std::string::npos);
}

// The geometric segments a frame was mapped with come back with their config key, so that a
// repair mapping the frame again skips the depth stages; they are kept only with masks.
TEST(FrameStore, GeometricSegmentsRoundTripWithTheirKey) {
  TempDir dir;
  const PanopticFrame p = segmentation();
  const GeometricSegments g{labels(4), 0x0123456789abcdefull};
  {
    FrameStore store(configIn(dir));
    for (int64_t utime : {10, 11, 12}) {
      store.add(utime, pose(0.5), camera(), 0.001, depth(3), LabelImage(kWidth, kHeight, 9),
                nullptr, &p, &g);
    }
    // Without masks there is no remap to use them: not stored.
    store.add(20, pose(0.5), camera(), 0.001, depth(3), LabelImage(kWidth, kHeight, 9), nullptr,
              nullptr, &g);
    EXPECT_GT(store.frameBytes(10).geometric, 0u);
    EXPECT_EQ(store.frameBytes(20).geometric, 0u);
    const GeometricSegments small{LabelImage(8, 8, 1), 1};
    expectError(
        [&] {
          store.add(30, pose(0.1), camera(), 0.001, depth(1), LabelImage(kWidth, kHeight, 1),
                    nullptr, &p, &small);
        },
        {"frame 30", "geometric segment image"});
    EXPECT_EQ(store.size(), 4u);
  }
  EXPECT_FALSE(fs::exists(dir.path("store/frames/20.geometric.zst")));
  flipByte(dir.path("store/frames/11.geometric.zst"), 3);
  {
    const auto store = FrameStore::open(dir.path("store"));
    EXPECT_EQ(store->utimes(), (std::vector<int64_t>{10, 12, 20}));
    ASSERT_EQ(store->problems().size(), 1u);
    EXPECT_NE(store->problems()[0].find("11.geometric.zst is corrupt"), std::string::npos)
        << store->problems()[0];
    const StoredFrame f = store->load(10);
    ASSERT_TRUE(f.has_panoptic);
    EXPECT_TRUE(f.geometric.ids == g.ids);
    EXPECT_EQ(f.geometric.config_key, g.config_key);
    EXPECT_TRUE(store->load(20).geometric.ids.empty());
  }
  // A crash that cuts the geometric line keeps the frame and its masks, without them.
  const std::string index = dir.path("store/index.txt");
  std::string text;
  {
    std::ifstream in(index);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const size_t last = text.rfind("geometric 12 ");
  ASSERT_NE(last, std::string::npos);
  fs::resize_file(index, last + 20);
  const auto store = FrameStore::open(dir.path("store"));
  const StoredFrame f = store->load(12);
  EXPECT_TRUE(f.has_panoptic);
  EXPECT_TRUE(f.geometric.ids.empty());
}

// A re-integration votes with depth and labels only: loading without the segmentation gives
// them bit for bit and never reads the segmentation's files (a damaged one does not matter).
TEST(FrameStore, LoadingWithoutTheSegmentationReadsDepthAndLabelsOnly) {
  TempDir dir;
  const PanopticFrame p = segmentation();
  const GeometricSegments g{labels(4), 0x0123456789abcdefull};
  const LabelImage votes = labels(2);
  {
    FrameStore store(configIn(dir));
    store.add(10, pose(0.5), camera(), 0.001, depth(3), votes, nullptr, &p, &g);
  }
  const auto store = FrameStore::open(dir.path("store"));
  const StoredFrame all = store->load(10);
  ASSERT_TRUE(all.has_panoptic);
  ASSERT_FALSE(all.geometric.ids.empty());
  for (const char* file : {"10.masks.zst", "10.segments.txt", "10.geometric.zst"}) {
    flipByte(dir.path(std::string("store/frames/") + file), 3);
  }
  const StoredFrame f = store->load(10, FrameStore::Parts::kWithoutSegmentation);
  EXPECT_FALSE(f.has_panoptic);
  EXPECT_TRUE(f.panoptic.segment_ids.empty());
  EXPECT_TRUE(f.panoptic.segments.empty());
  EXPECT_TRUE(f.geometric.ids.empty());
  EXPECT_TRUE(f.rgbd.depth == all.rgbd.depth);
  EXPECT_TRUE(f.labels == votes);
  expectSamePose(f.T_W_C, all.T_W_C);
  EXPECT_EQ(f.rgbd.camera.fx, all.rgbd.camera.fx);
  // The whole frame still checks every file.
  expectError([&] { store->load(10); }, {"frame 10", "differs"});
}

TEST(FrameStore, ThreadsAddingAtOnceLoseNoFrame) {
  TempDir dir;
  FrameStore store(configIn(dir));
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t) {
    threads.emplace_back([&store, t] {
      for (int i = t; i < 12; i += 2) addFrame(&store, i);
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(store.size(), 12u);
  const auto reopened = FrameStore::open(dir.path("store"));
  EXPECT_TRUE(reopened->problems().empty()) << reopened->problems().front();
  ASSERT_EQ(reopened->size(), 12u);
  for (int i = 0; i < 12; ++i) expectFrame(reopened->load(1000 + i), i);
}

}  // namespace
}  // namespace panmap
