#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/text_files.h"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/log_import.h"
#include "panmap/lcm/log_info.h"
#include "scannet_sens_fixture.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;

// Every event of a log, in order.
struct Event {
  std::string channel;
  int64_t timestamp;
  std::vector<uint8_t> data;
};
std::vector<Event> readEvents(const std::string& path) {
  lcm::LogFile log(path, "r");
  EXPECT_TRUE(log.good());
  std::vector<Event> events;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    const auto* d = static_cast<const uint8_t*>(e->data);
    events.push_back({e->channel, e->timestamp, std::vector<uint8_t>(d, d + e->datalen)});
  }
  return events;
}

template <typename Msg>
Msg decodeEvent(const Event& e) {
  Msg msg;
  EXPECT_EQ(msg.decode(e.data.data(), 0, static_cast<int>(e.data.size())),
            static_cast<int>(e.data.size()));
  return msg;
}

// The 7-Scenes log is imported once for all tests of this suite.
class SevenScenesLog : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!fs::is_directory(test::dataDir("7scenes-200"))) return;
    dir_ = new test::TempDir;
    stats_ = importDataset(test::dataDir("7scenes-200"), dir_->path("7s.lcmlog"), ImportOptions{});
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override { PANMAP_REQUIRE_DATA("7scenes-200"); }
  static std::string logPath() { return dir_->path("7s.lcmlog"); }

  static test::TempDir* dir_;
  static ImportStats stats_;
};
test::TempDir* SevenScenesLog::dir_ = nullptr;
ImportStats SevenScenesLog::stats_;

TEST_F(SevenScenesLog, EveryFrameAndPoseIsWritten) {
  EXPECT_EQ(stats_.frames_written, 200u);
  EXPECT_EQ(stats_.poses_written, 200u);
  EXPECT_EQ(stats_.panoptic_written, 0u);
  EXPECT_EQ(stats_.skipped_invalid_pose, 0u);
  EXPECT_FALSE(fs::exists(logPath() + ".partial"));
}

TEST_F(SevenScenesLog, DepthIsBitIdenticalAndPosesEqualTheFiles) {
  const std::vector<Event> events = readEvents(logPath());
  ASSERT_EQ(events.size(), 400u);
  size_t frames = 0, poses = 0;
  int64_t last = -1;
  for (const Event& e : events) {
    EXPECT_GE(e.timestamp, last);
    last = e.timestamp;
    if (e.channel == "CAMERA_RGBD") {
      const RgbdFrame f = fromMessage(decodeEvent<rgbd_frame_t>(e));
      char name[64];
      std::snprintf(name, sizeof(name), "7scenes-200/frame-%06lld",
                    static_cast<long long>(f.frame_id));
      const cv::Mat png = cv::imread(test::dataDir(name) + ".depth.png", cv::IMREAD_UNCHANGED);
      ASSERT_EQ(png.type(), CV_16UC1);
      ASSERT_EQ(f.depth.width(), png.cols);
      ASSERT_EQ(f.depth.height(), png.rows);
      EXPECT_EQ(std::memcmp(png.data, f.depth.data(), f.depth.size() * 2), 0) << name;
      EXPECT_EQ(f.utime, e.timestamp);
      EXPECT_EQ(f.utime, std::llround(f.frame_id * 1e6 / 30.0));
      ++frames;
    } else if (e.channel == "CAMERA_POSE") {
      const StampedPose p = fromMessage(decodeEvent<pose_t>(e));
      char name[64];
      std::snprintf(name, sizeof(name), "7scenes-200/frame-%06lld.pose.txt",
                    static_cast<long long>(p.frame_id));
      const Eigen::MatrixXd file = readMatrixFile(test::dataDir(name), 4, 4);
      // Translation exactly; rotation to the file's own rounding (|R^T R - I| < 3e-4).
      EXPECT_EQ(p.T_W_C.translation(), Eigen::Vector3d(file.topRightCorner<3, 1>())) << name;
      EXPECT_LT((p.T_W_C.linear() - file.topLeftCorner<3, 3>()).cwiseAbs().maxCoeff(), 5e-4)
          << name;
      EXPECT_EQ(p.source, PoseSource::kGroundTruth);
      ++poses;
    }
  }
  EXPECT_EQ(frames, 200u);
  EXPECT_EQ(poses, 200u);
}

TEST_F(SevenScenesLog, LogInfoDecodesEverything) {
  const LogInfo info = inspectLog(logPath(), true);
  EXPECT_TRUE(info.allDecoded());
  EXPECT_EQ(info.events, 400u);
  ASSERT_EQ(info.channels.size(), 2u);
  const ChannelInfo& pose = info.channels[0];
  const ChannelInfo& rgbd = info.channels[1];
  EXPECT_EQ(pose.channel, "CAMERA_POSE");
  EXPECT_EQ(rgbd.type, "rgbd_frame_t");
  EXPECT_EQ(rgbd.count, 200u);
  EXPECT_EQ(rgbd.first_utime, 0);
  EXPECT_EQ(rgbd.last_utime, 19900000);    // frame 597 at 30 Hz
  EXPECT_NEAR(rgbd.rateHz(), 10.0, 1e-9);  // every third frame of a 30 Hz recording
  const auto json = nlohmann::json::parse(logInfoToJson(info));
  EXPECT_EQ(json["channels"][1]["count"], 200);
  EXPECT_EQ(json["all_decoded"], true);
}

TEST_F(SevenScenesLog, TruncatedAndCorruptLogsAreReported) {
  const std::vector<uint8_t> bytes = readFileBytes(logPath());
  test::TempDir dir;
  std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + bytes.size() / 2);
  writeFileBytes(dir.path("cut.lcmlog"), cut);
  const LogInfo truncated = inspectLog(dir.path("cut.lcmlog"), false);
  EXPECT_TRUE(truncated.truncated);
  EXPECT_FALSE(truncated.allDecoded());
  EXPECT_GT(truncated.events, 100u);

  // Flip a byte inside the first frame's depth PNG: the message decodes, its image does not.
  std::vector<uint8_t> corrupt = bytes;
  const auto events = readEvents(logPath());
  // Event header: sync word, event number, timestamp, channel and data lengths, channel.
  const size_t header = 4 + 8 + 8 + 4 + 4 + events[0].channel.size();
  ASSERT_EQ(events[0].channel, "CAMERA_RGBD");
  for (size_t i = header + events[0].data.size() - 2000; i < header + events[0].data.size() - 1000;
       ++i)
    corrupt[i] ^= 0x5A;
  writeFileBytes(dir.path("corrupt.lcmlog"), corrupt);
  const LogInfo deep = inspectLog(dir.path("corrupt.lcmlog"), true);
  EXPECT_FALSE(deep.truncated);
  EXPECT_EQ(deep.channels[1].failures, 1u);
  EXPECT_FALSE(deep.channels[1].first_error.empty());
  EXPECT_THROW(inspectLog(dir.path("missing.lcmlog"), true), Error);

  // Garbage between two events: LCM's reader stops there; loginfo reports the unread rest.
  std::vector<uint8_t> gap(bytes.begin(), bytes.begin() + header + events[0].data.size());
  gap.insert(gap.end(), 37, 0xAB);
  gap.insert(gap.end(), bytes.begin() + header + events[0].data.size(), bytes.end());
  writeFileBytes(dir.path("gap.lcmlog"), gap);
  const LogInfo skipped = inspectLog(dir.path("gap.lcmlog"), false);
  EXPECT_LT(skipped.events, 400u);
  EXPECT_TRUE(skipped.truncated);
  EXPECT_FALSE(skipped.allDecoded());
}

TEST(Import, RawImagesAreExact) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  ImportOptions options;
  options.max_frames = 3;
  options.encoding.color = image_t::COMPRESSION_NONE;
  options.encoding.depth = image_t::COMPRESSION_NONE;
  importDataset(test::dataDir("7scenes-200"), dir.path("raw.lcmlog"), options);
  const auto events = readEvents(dir.path("raw.lcmlog"));
  ASSERT_EQ(events.size(), 6u);
  const rgbd_frame_t msg = decodeEvent<rgbd_frame_t>(events[2]);
  EXPECT_EQ(msg.depth.compression, +image_t::COMPRESSION_NONE);
  EXPECT_EQ(msg.depth.row_stride, 1280);
  const ColorImage jpeg = readColorFile(test::dataDir("7scenes-200/frame-000003.color.jpg"));
  EXPECT_EQ(fromMessage(msg).color, jpeg);
}

TEST(Import, ScanNetSkipsInvalidPosesWithACount) {
  PANMAP_REQUIRE_DATA("scannet-export-3");
  test::TempDir dir;
  test::makeScanNetExportWithInfPose(dir);
  const ImportStats s = importDataset(dir.path(), dir.path("s.lcmlog"), ImportOptions{});
  EXPECT_EQ(s.frames_written, 2u);
  EXPECT_EQ(s.skipped_invalid_pose, 1u);
  EXPECT_NE(s.first_skip_reason.find("pose/1.txt"), std::string::npos);
  const auto events = readEvents(dir.path("s.lcmlog"));
  ASSERT_EQ(events.size(), 4u);
  const RgbdFrame f = fromMessage(decodeEvent<rgbd_frame_t>(events[2]));
  EXPECT_EQ(f.frame_id, 2);  // frame 1 is not in the log
  EXPECT_EQ(f.color.width(), 640);

  ImportOptions strict;
  strict.invalid_pose = ImportOptions::InvalidPose::kError;
  EXPECT_THROW(importDataset(dir.path(), dir.path("t.lcmlog"), strict), Error);
  EXPECT_FALSE(fs::exists(dir.path("t.lcmlog")));
  EXPECT_FALSE(fs::exists(dir.path("t.lcmlog.partial")));
}

TEST(Import, NoFrameWithAPoseIsAnErrorEvenWhenSkipping) {
  // tum_tiny with its ground truth an hour later than every frame: skipping leaves nothing.
  test::TempDir dir;
  fs::copy(test::fixtureDir("tum_tiny"), dir.path("t"), fs::copy_options::recursive);
  std::ofstream(dir.path("t/groundtruth.txt"), std::ios::trunc)
      << "3600.0 0 0 0 0 0 0 1\n3600.1 0 0 0 0 0 0 1\n";
  ImportOptions skip;
  skip.invalid_pose = ImportOptions::InvalidPose::kSkip;
  try {
    importDataset(dir.path("t"), dir.path("t.lcmlog"), skip);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no frame has a valid pose: all 3"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.path("t.lcmlog")));
  EXPECT_FALSE(fs::exists(dir.path("t.lcmlog.partial")));
}

TEST(Import, TumStopsOnAMissingPoseUnlessAskedToSkip) {
  test::TempDir dir;
  try {
    importDataset(test::fixtureDir("tum_tiny"), dir.path("t.lcmlog"), ImportOptions{});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("groundtruth.txt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--invalid-poses skip"), std::string::npos) << e.what();
  }
  ImportOptions skip;
  skip.invalid_pose = ImportOptions::InvalidPose::kSkip;
  const ImportStats s = importDataset(test::fixtureDir("tum_tiny"), dir.path("t.lcmlog"), skip);
  EXPECT_EQ(s.frames_written, 2u);
  EXPECT_EQ(s.unmatched_frames, 1u);
  const auto events = readEvents(dir.path("t.lcmlog"));
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(events[0].timestamp, 1005000);  // real timestamps
  EXPECT_EQ(events[2].timestamp, 1040000);
  const RgbdFrame f = fromMessage(decodeEvent<rgbd_frame_t>(events[0]));
  EXPECT_DOUBLE_EQ(f.depth_scale_m, 0.0002);
  EXPECT_EQ(f.depth(3, 2), 5003);
}

// Imports the first max_frames frames of 7scenes-200 into DIR/m.lcmlog with one COCO panoptic
// mask (PNG + its JSON) for the first frame, read through the given label table.
ImportStats importWithFirstMask(const test::TempDir& dir, const LabelImage& mask,
                                const std::string& segments_json, const std::string& label_table,
                                size_t max_frames, bool contiguous_ids = false,
                                bool resize_masks = false) {
  fs::create_directory(dir.path("masks"));
  writeFileBytes(dir.path("masks/frame-000000.color.png"), encodeLabelPng(mask));
  std::ofstream(dir.path("masks/frame-000000.color.json")) << segments_json;
  ImportOptions options;
  options.max_frames = max_frames;
  options.mask_dir = dir.path("masks");
  options.label_table = label_table;
  options.contiguous_ids = contiguous_ids;
  options.resize_masks = resize_masks;
  return importDataset(test::dataDir("7scenes-200"), dir.path("m.lcmlog"), options);
}

TEST(Import, PanopticMasksBecomeMessages) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  // A full-size mask for the first frame only: left half wall, a chair box, the rest void.
  LabelImage mask(640, 480, 0);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 320; ++u) mask(u, v) = 1;
  }
  for (int v = 100; v < 200; ++v) {
    for (int u = 400; u < 500; ++u) mask(u, v) = 300;
  }
  const ImportStats s = importWithFirstMask(
      dir, mask,
      R"({"segments_info": [{"id": 1, "category_id": 1}, {"id": 300, "category_id": 62, "score": 0.9}]})",
      test::fixtureDir("coco_tiny/labels.tsv"), 2);
  EXPECT_EQ(s.panoptic_written, 1u);
  EXPECT_EQ(s.frames_without_mask, 1u);
  const auto events = readEvents(dir.path("m.lcmlog"));
  ASSERT_EQ(events.size(), 5u);
  EXPECT_EQ(events[2].channel, "PANOPTIC");
  const PanopticFrame p = fromMessage(decodeEvent<panoptic_t>(events[2]));
  EXPECT_EQ(p.utime, 0);
  EXPECT_EQ(p.segment_ids, mask);
  ASSERT_EQ(p.segments.size(), 2u);
  EXPECT_EQ(p.segments[1], (PanopticSegment{300, 5, 62, true, 0.9f}));
  EXPECT_TRUE(inspectLog(dir.path("m.lcmlog"), true).allDecoded());
  EXPECT_EQ(s.mask_pixels, 320u * 480u + 100u * 100u);
  EXPECT_EQ(s.unlisted_mask_pixels, 0u);
}

// A ScanNet recording with a network's mask for one frame, at the colour camera's 1296x968 and
// named by frame number as SensReader names the colour it exports: the mask arrives registered
// to the 640x480 depth camera, with its classes, on that frame only.
TEST(Import, MasksOfAScanNetRecordingAreRegisteredToItsDepth) {
  PANMAP_REQUIRE_DATA("scannet-export-3");
  test::TempDir dir;
  test::writeScanNetExportAsSens(dir.path("scene0707_00.sens"));
  LabelImage mask(1296, 968, 1);  // wall
  for (int v = 0; v < 968; ++v) {
    for (int u = 648; u < 1296; ++u) mask(u, v) = 300;  // the right half: a chair
  }
  fs::create_directory(dir.path("masks"));
  writeFileBytes(dir.path("masks/1.png"), encodeLabelPng(mask));
  std::ofstream(dir.path("masks/1.json"))
      << R"({"segments_info": [{"id": 1, "category_id": 1}, {"id": 300, "category_id": 62, )"
         R"("score": 0.9}]})";
  ImportOptions options;
  options.mask_dir = dir.path("masks");
  options.label_table = test::fixtureDir("coco_tiny/labels.tsv");
  const ImportStats s = importDataset(dir.path("scene0707_00.sens"), dir.path("s.lcmlog"), options);
  EXPECT_EQ(s.layout, "scannet-sens");
  EXPECT_EQ(s.frames_written, 3u);
  EXPECT_EQ(s.panoptic_written, 1u);
  EXPECT_EQ(s.frames_without_mask, 2u);
  size_t found = 0;
  for (const Event& e : readEvents(dir.path("s.lcmlog"))) {
    if (e.channel != "PANOPTIC") continue;
    ++found;
    const PanopticFrame p = fromMessage(decodeEvent<panoptic_t>(e));
    EXPECT_EQ(p.frame_id, 1);
    ASSERT_EQ(p.segment_ids.width(), 640);
    ASSERT_EQ(p.segment_ids.height(), 480);
    EXPECT_EQ(p.segment_ids(20, 240), 1);
    EXPECT_EQ(p.segment_ids(620, 240), 300);
    ASSERT_EQ(p.segments.size(), 2u);
    EXPECT_EQ(p.segments[1], (PanopticSegment{300, 5, 62, true, 0.9f}));
  }
  EXPECT_EQ(found, 1u);
}

// Id 300 (R 44, G 1) written by cv2.imwrite from an RGB array: B 44, G 1, read back as
// 1 * 256 + 44 * 65536.
constexpr int32_t kId300AsBgr = 256 + 44 * 65536;

// Pixels whose id segments_info does not list were left void with nothing said: a network's
// PNG saved as BGR gave an empty map and exit 0. A few are counted and named; most refuse the
// import, naming the swap when it would have matched them.
TEST(Import, MaskPixelsOfUnlistedIdsAreCountedAndMostlyUnlistedMasksRefused) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  const std::string json =
      R"({"segments_info": [{"id": 1, "category_id": 1}, {"id": 300, "category_id": 62}]})";
  LabelImage mask(640, 480, 0);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 320; ++u) mask(u, v) = 1;
  }
  for (int v = 100; v < 200; ++v) {
    for (int u = 400; u < 500; ++u) mask(u, v) = kId300AsBgr;
  }
  {
    test::TempDir dir;
    const ImportStats s =
        importWithFirstMask(dir, mask, json, test::fixtureDir("coco_tiny/labels.tsv"), 1);
    EXPECT_EQ(s.mask_pixels, 320u * 480u + 100u * 100u);
    EXPECT_EQ(s.unlisted_mask_pixels, 100u * 100u);
    EXPECT_EQ(s.unlisted_bgr_mask_pixels, 100u * 100u);
    EXPECT_EQ(unlistedMaskPixels(s),
              "masks: 6.1 % of the pixels with a segment id carry an id their segments_info does "
              "not list (left unlabelled); with R and B swapped 100.0 % of them would match: the "
              "PNGs look written as BGR (cv2.imwrite of an RGB array; "
              "cv2.cvtColor(ids_rgb, cv2.COLOR_RGB2BGR) before writing)");
    const PanopticFrame p =
        fromMessage(decodeEvent<panoptic_t>(readEvents(dir.path("m.lcmlog"))[2]));
    EXPECT_EQ(p.segment_ids(450, 150), 0);  // void, as COCO reads it
    EXPECT_EQ(p.segment_ids(10, 10), 1);
    EXPECT_EQ(p.segment_ids(620, 450), 0);
  }
  // The whole mask written as BGR: id 1 reads as 65536.
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 320; ++u) mask(u, v) = 65536;
  }
  test::TempDir dir;
  test::expectError(
      [&] { importWithFirstMask(dir, mask, json, test::fixtureDir("coco_tiny/labels.tsv"), 1); },
      {"masks: 100.0 % of the pixels", "the PNGs look written as BGR", "not imported"});
  EXPECT_FALSE(fs::exists(dir.path("m.lcmlog")));
}

// Mask files no frame took (numbered otherwise than the images, say) were never mentioned:
// counted, the first named.
TEST(Import, MasksNoFrameTookAreCountedAndTheFirstNamed) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  fs::create_directory(dir.path("masks"));
  for (const std::string stem : {"frame-000000.color", "frame-000999.color"}) {
    writeFileBytes(dir.path("masks/" + stem + ".png"), encodeLabelPng(LabelImage(640, 480, 1)));
    std::ofstream(dir.path("masks/" + stem + ".json"))
        << R"({"segments_info": [{"id": 1, "category_id": 1}]})";
  }
  ImportOptions options;
  options.max_frames = 2;
  options.mask_dir = dir.path("masks");
  const ImportStats s = importDataset(test::dataDir("7scenes-200"), dir.path("m.lcmlog"), options);
  EXPECT_EQ(s.panoptic_written, 1u);
  EXPECT_EQ(s.masks_found, 2u);
  EXPECT_EQ(s.masks_unused, 1u);
  EXPECT_EQ(s.first_unused_mask, "frame-000999.color");
}

// Masks that match no frame by name are an error, not a map without classes: the message
// names the file name the first frame's mask would have. No log is left behind.
TEST(Import, MasksMatchingNoFrameAreNamed) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  fs::create_directory(dir.path("masks"));
  writeFileBytes(dir.path("masks/frame-000000.png"), encodeLabelPng(LabelImage(640, 480, 1)));
  std::ofstream(dir.path("masks/frame-000000.json"))
      << R"({"segments_info": [{"id": 1, "category_id": 1}]})";
  ImportOptions options;
  options.max_frames = 2;
  options.mask_dir = dir.path("masks");
  options.label_table = test::fixtureDir("coco_tiny/labels.tsv");
  test::expectError(
      [&] { importDataset(test::dataDir("7scenes-200"), dir.path("m.lcmlog"), options); },
      {"no mask in " + dir.path("masks") + " matches a frame",
       "its mask 'frame-000000.color.png'"});
  EXPECT_FALSE(fs::exists(dir.path("m.lcmlog")));
  EXPECT_FALSE(fs::exists(dir.path("m.lcmlog.partial")));
}

TEST(Import, CocoNetworkMasksTakeTheShippedTablesClasses) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  // What Detectron2's COCOPanopticEvaluator writes for a COCO-trained network: COCO category
  // ids, an isthing flag per segment, a score per thing.
  LabelImage mask(640, 480, 0);
  const int32_t ids[] = {1, 2, 3, 4, 5};
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) mask(u, v) = ids[std::min(u / 128, 4)];
  }
  const ImportStats s = importWithFirstMask(dir, mask, R"({"segments_info": [
      {"id": 1, "category_id": 199, "isthing": 0},
      {"id": 2, "category_id": 190, "isthing": 0},
      {"id": 3, "category_id": 62, "isthing": 1, "score": 0.8},
      {"id": 4, "category_id": 188, "isthing": 0},
      {"id": 5, "category_id": 3, "isthing": 1, "score": 0.6}]})",
                                            test::shippedLabelTable("coco_panoptic_nyu40.tsv"), 1);
  EXPECT_EQ(s.panoptic_written, 1u);
  EXPECT_EQ(s.unknown_category_segments, 0u);  // a car is known: the table voids it
  const auto events = readEvents(dir.path("m.lcmlog"));
  ASSERT_EQ(events.size(), 3u);
  const PanopticFrame p = fromMessage(decodeEvent<panoptic_t>(events[2]));
  ASSERT_EQ(p.segments.size(), 5u);
  EXPECT_EQ(p.segments[0], (PanopticSegment{1, 1, 199, false, 1.0f}));  // wall
  EXPECT_EQ(p.segments[1], (PanopticSegment{2, 2, 190, false, 1.0f}));  // floor
  EXPECT_EQ(p.segments[2], (PanopticSegment{3, 5, 62, true, 0.8f}));    // chair
  EXPECT_EQ(p.segments[3], (PanopticSegment{4, 3, 188, false, 1.0f}));  // cabinet, as stuff
  EXPECT_EQ(p.segments[4], (PanopticSegment{5, 0, 3, true, 0.6f}));     // car: void
}

// The one PANOPTIC message of a log of one frame (CAMERA_RGBD, CAMERA_POSE, PANOPTIC), or an
// empty frame and a failure.
PanopticFrame onlyPanoptic(const std::string& log) {
  const auto events = readEvents(log);
  if (events.size() != 3u || events[2].channel != "PANOPTIC") {
    ADD_FAILURE() << log << ": " << events.size() << " events, not a frame and its mask";
    return PanopticFrame{};
  }
  return fromMessage(decodeEvent<panoptic_t>(events[2]));
}

TEST(Import, ContiguousIdsOfANetworksRawOutputTakeTheSameClasses) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  // The frame above as Mask2Former's post-processing numbers it: class indices 0-132 in
  // COCO's order instead of COCO's ids (wall 131, floor 122, chair 56, cabinet 120, car 2).
  const std::string segments = R"({"segments_info": [
      {"id": 1, "category_id": 131, "isthing": 0},
      {"id": 2, "category_id": 122, "isthing": 0},
      {"id": 3, "category_id": 56, "isthing": 1, "score": 0.8},
      {"id": 4, "category_id": 120, "isthing": 0},
      {"id": 5, "category_id": 2, "isthing": 1, "score": 0.6}]})";
  LabelImage mask(640, 480, 0);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) mask(u, v) = 1 + std::min(u / 128, 4);
  }
  const std::string table = test::shippedLabelTable("coco_panoptic_nyu40.tsv");
  test::TempDir dir;
  const ImportStats s = importWithFirstMask(dir, mask, segments, table, 1, true);
  EXPECT_EQ(s.unknown_category_segments, 0u);
  const PanopticFrame p = onlyPanoptic(dir.path("m.lcmlog"));
  ASSERT_EQ(p.segments.size(), 5u);
  const int32_t classes[] = {1, 2, 5, 3, 0};  // wall, floor, chair, cabinet, void
  for (size_t i = 0; i < 5; ++i) EXPECT_EQ(p.segments[i].category, classes[i]) << i;
  EXPECT_EQ(p.segments[2].source_category, 56);  // the network's own id is kept

  // Read as COCO ids, the same indices are other classes or none: 56 is broccoli (otherprop),
  // 131 and 122 are gaps in COCO's numbering.
  test::TempDir as_coco;
  const ImportStats t = importWithFirstMask(as_coco, mask, segments, table, 1, false);
  EXPECT_EQ(t.unknown_category_segments, 2u);
  const PanopticFrame q = onlyPanoptic(as_coco.path("m.lcmlog"));
  ASSERT_EQ(q.segments.size(), 5u);
  EXPECT_EQ(q.segments[2].category, 40);
}

TEST(Import, MasksOfAScaledImageAreScaledToItOnRequest) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  // A network run on the 640x480 frame scaled to 160x120: columns of 4 pixels each, so the
  // mask scaled back is known pixel for pixel (7-Scenes' colour is registered to its depth).
  LabelImage small(160, 120, 0);
  for (int v = 0; v < 120; ++v) {
    for (int u = 0; u < 160; ++u) small(u, v) = u < 40 ? 1 : (v < 60 ? 2 : 0);
  }
  const std::string segments =
      R"({"segments_info": [{"id": 1, "category_id": 1}, {"id": 2, "category_id": 5}]})";
  test::TempDir refused;
  try {
    importWithFirstMask(refused, small, segments, "", 1);
    FAIL() << "a mask of another size was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mask is 160x120 but its colour image is 640x480"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("--resize-masks"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(refused.path("m.lcmlog")));

  test::TempDir dir;
  const ImportStats s = importWithFirstMask(dir, small, segments, "", 1, false, true);
  EXPECT_EQ(s.masks_resized, 1u);
  const PanopticFrame p = onlyPanoptic(dir.path("m.lcmlog"));
  LabelImage expected(640, 480, 0);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) expected(u, v) = small(u / 4, v / 4);
  }
  EXPECT_EQ(p.segment_ids, expected);

  // Another shape (a square network input, padded) cannot be scaled back: an error.
  test::TempDir square;
  EXPECT_THROW(importWithFirstMask(square, LabelImage(120, 120, 1), segments, "", 1, false, true),
               Error);
}

TEST(Import, SemanticMasksBecomePanopticMessages) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  // A semantic network's output for the first frame: ADE20K ids, wall (0) on the left half,
  // two chairs (19) apart on the right, floor (3) below them.
  cv::Mat ids(480, 640, CV_8UC1, cv::Scalar(3));
  ids(cv::Rect(0, 0, 320, 480)).setTo(0);
  ids(cv::Rect(360, 100, 80, 80)).setTo(19);
  ids(cv::Rect(500, 100, 80, 80)).setTo(19);
  ids(cv::Rect(600, 400, 40, 80)).setTo(255);  // the network's "ignore": no class
  test::TempDir dir;
  fs::create_directory(dir.path("masks"));
  ASSERT_TRUE(cv::imwrite(dir.path("masks/frame-000000.color.png"), ids));
  ImportOptions options;
  options.max_frames = 1;
  options.mask_dir = dir.path("masks");
  options.mask_format = ImportOptions::MaskFormat::kSemantic;
  options.label_table = test::shippedLabelTable("ade20k_nyu40.tsv");
  const ImportStats s = importDataset(test::dataDir("7scenes-200"), dir.path("m.lcmlog"), options);
  EXPECT_EQ(s.panoptic_written, 1u);
  EXPECT_EQ(s.unknown_category_segments, 0u);
  EXPECT_EQ(s.mask_void_ids, (std::set<int32_t>{255}));
  const PanopticFrame p = onlyPanoptic(dir.path("m.lcmlog"));
  ASSERT_EQ(p.segments.size(), 4u);
  EXPECT_EQ(p.segments[0], (PanopticSegment{1, 1, 0, false, 1.0f}));  // wall
  EXPECT_EQ(p.segments[1], (PanopticSegment{2, 2, 3, false, 1.0f}));  // floor
  EXPECT_EQ(p.segments[2], (PanopticSegment{3, 5, 19, true, 1.0f}));  // chair, left
  EXPECT_EQ(p.segments[3], (PanopticSegment{4, 5, 19, true, 1.0f}));  // chair, right
  EXPECT_EQ(p.segment_ids(400, 140), 3);
  EXPECT_EQ(p.segment_ids(540, 140), 4);
  EXPECT_EQ(p.segment_ids(10, 10), 1);

  // A COCO JSON means the masks are not semantic: the options contradict each other.
  options.mask_json = dir.path("masks/panoptic.json");
  EXPECT_THROW(importDataset(test::dataDir("7scenes-200"), dir.path("n.lcmlog"), options), Error);
}

}  // namespace
}  // namespace panmap
