// The mapping session shared by the offline reader and the live process: every kind of bad
// input is refused with a counted reason and leaves the map exactly as a clean run makes it.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <tuple>

#include "panmap/lcm/correction_conversions.h"
#include "panmap/lcm/mapping_session.h"
#include "synthetic_stream.h"
#include "test_helpers.h"

namespace panmap {
namespace {

void feed(MappingSession* session, const std::vector<test::Encoded>& messages) {
  for (const test::Encoded& m : messages)
    session->handle(m.channel, m.bytes.data(), m.bytes.size());
  session->flush();
}

// A frame store in a temporary folder, and session options that write to it.
struct TempStore {
  TempStore() : store(config()) {}
  FrameStoreConfig config() const {
    FrameStoreConfig c;
    c.folder = dir.path("store");
    return c;
  }
  SessionOptions options() {
    SessionOptions o;
    o.frame_store = &store;
    return o;
  }
  test::TempDir dir;  // first: the store's folder is in it
  FrameStore store;
};

class MappingSessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    stream_ = test::syntheticStream();
    Mapper mapper(test::streamMapperConfig());
    MappingSession session(SessionOptions{}, &mapper);
    feed(&session, stream_.messages());
    clean_ = test::mapBytes(mapper);
    clean_stats_ = session.stats();
  }
  test::SyntheticStream stream_;
  std::string clean_;
  SessionStats clean_stats_;
};

TEST_F(MappingSessionTest, CleanStreamMapsEveryFrame) {
  EXPECT_EQ(clean_stats_.frames_integrated, static_cast<int64_t>(stream_.frames.size()));
  EXPECT_EQ(clean_stats_.frames_received, static_cast<int64_t>(stream_.frames.size()));
  EXPECT_TRUE(clean_stats_.rejected.empty());
  EXPECT_EQ(clean_stats_.sync.geometry_only, 0);
  EXPECT_EQ(clean_stats_.timings.count("total"), 1u);
  // Ground-truth poses are never tracked, so refinement moved none.
  EXPECT_EQ(clean_stats_.refinement.frames, 0);
  EXPECT_EQ(clean_stats_.refinement.moved_m.max, 0.0);
}

TEST_F(MappingSessionTest, ANetworkSlowerThanTheCameraDelaysNoFrameAndIsNamed) {
  // Masks for every third frame: the frames between go on as soon as the next mask shows the
  // network skipped them (they waited 0.5 s of stream time each, and the queue filled).
  std::vector<test::Encoded> messages;
  const size_t n = stream_.frames.size();
  for (size_t k = 0; k < n; ++k) {
    messages.push_back(test::encodeMessage("CAMERA_POSE", toMessage(stream_.poses[k])));
    if (k % 3 == 0) {
      messages.push_back(
          test::encodeMessage("PANOPTIC", toMessage(stream_.masks[k], ImageEncoding{})));
    }
    messages.push_back(
        test::encodeMessage("CAMERA_RGBD", toMessage(stream_.frames[k], ImageEncoding{})));
  }
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(SessionOptions{}, &mapper);
  for (const test::Encoded& m : messages) session.handle(m.channel, m.bytes.data(), m.bytes.size());
  // Before the end of the stream: all but the frames after the last mask are mapped.
  EXPECT_EQ(session.stats().frames_integrated, static_cast<int64_t>(n - (n - 1) % 3));
  session.flush();
  const SessionStats stats = session.stats();
  EXPECT_EQ(stats.frames_integrated, static_cast<int64_t>(n));
  EXPECT_TRUE(stats.rejected.empty());
  const int64_t without = static_cast<int64_t>(n - (n + 2) / 3);
  EXPECT_EQ(stats.sync.geometry_only, without);
  const std::vector<std::string> warnings = syncWarnings(stats, SyncConfig{});
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("panoptic: " + std::to_string(without) + " of " + std::to_string(n) +
                             " frames mapped without a mask"),
            std::string::npos)
      << warnings[0];
  EXPECT_TRUE(syncWarnings(clean_stats_, SyncConfig{}).empty());
}

TEST_F(MappingSessionTest, RefinementReportsHowFarItMovedTheGivenPoses) {
  // The same frames with their poses flagged as SLAM, one of them 3 cm off along x: tracking
  // refines every frame after the warm-up and pulls that one back by about its error.
  test::SyntheticStream slam = stream_;
  for (StampedPose& p : slam.poses) p.source = PoseSource::kSlam;
  const size_t off = slam.poses.size() - 3;
  slam.poses[off].T_W_C.translation().x() += 0.03;
  MapperConfig config = test::streamMapperConfig();
  // 160 x 120 frames: every other pixel, or too few points reach the map to align.
  config.tracking.level_strides_px = {4, 2};
  config.depth_check.frames = 0;  // rendered depth: trusted without auto's check
  Mapper mapper(config);
  MappingSession session(SessionOptions{}, &mapper);
  feed(&session, slam.messages());
  const PoseRefinementStats& r = session.stats().refinement;
  EXPECT_EQ(mapper.trackingCounts()[static_cast<size_t>(AlignmentStatus::kAccepted)] +
                mapper.trackingCounts()[static_cast<size_t>(AlignmentStatus::kAcceptedPartially)],
            r.frames);
  EXPECT_EQ(r.frames, static_cast<int64_t>(slam.frames.size()) - config.tracking_warmup_frames);
  EXPECT_EQ(mapper.posesCorrected(), r.frames);
  EXPECT_EQ(mapper.posesKeptAsGiven(), 0);
  EXPECT_GT(r.moved_m.max, 0.02);
  EXPECT_LT(r.moved_m.max, 0.04);
  EXPECT_LT(r.moved_m.median, 0.01);
  EXPECT_LE(r.moved_m.median, r.moved_m.p95);
  EXPECT_LE(r.moved_m.p95, r.moved_m.max);
  EXPECT_GE(r.turned_deg.median, 0.0);
  EXPECT_LE(r.turned_deg.median, r.turned_deg.max);
}

// Depth with a fixed error pattern and SLAM poses: auto refines the first frames, the depth
// check finds the pattern and takes them back to their given poses; the frame store then holds
// the poses the map holds them at, so a later repair or a reopened store starts from those.
TEST_F(MappingSessionTest, TheFrameStoreKeepsThePosesTheDepthCheckRevertedTo) {
  const test::SyntheticStream& source = test::syntheticStream(16);
  test::SyntheticStream slam = source;
  for (size_t k = 0; k < slam.poses.size(); ++k) {
    slam.poses[k].source = PoseSource::kSlam;
    // A few millimetres off, growing: refinement has something to correct.
    slam.poses[k].T_W_C.translation().x() += 0.001 * static_cast<double>(k);
    DepthImage& depth = slam.frames[k].depth;
    for (int v = 0; v < depth.height(); ++v) {
      for (int u = 0; u < depth.width(); ++u) {
        uint16_t& d = depth(u, v);  // 20 px squares 8 mm long and short: no rigid motion
        if (d > 8) d = static_cast<uint16_t>((u / 20 + v / 20) % 2 ? d + 8 : d - 8);
      }
    }
  }
  MapperConfig config = test::streamMapperConfig();
  config.tracking.level_strides_px = {4, 2};
  config.depth_check.frames = 6;  // 16 frames: a verdict after the warm-up and 6 alignments
  config.depth_check.min_cell_frames = 2;
  TempStore temp;
  FrameStore& store = temp.store;
  Mapper mapper(config);
  MappingSession session(temp.options(), &mapper);
  feed(&session, slam.messages());
  ASSERT_EQ(mapper.depthCheck().verdict(), DepthPatternMonitor::Verdict::kUncalibrated);
  EXPECT_TRUE(session.stats().rejected.empty());
  ASSERT_EQ(store.size(), slam.frames.size());
  const std::vector<StampedPose>& trajectory = mapper.trajectory();
  ASSERT_EQ(trajectory.size(), slam.poses.size());
  for (size_t k = 0; k < trajectory.size(); ++k) {
    // The given poses (as LCM carried them: a quaternion, so not to the last bit).
    EXPECT_TRUE(trajectory[k].T_W_C.isApprox(slam.poses[k].T_W_C, 1e-9)) << k;
    EXPECT_TRUE(store.load(trajectory[k].utime).T_W_C.isApprox(trajectory[k].T_W_C, 0.0)) << k;
  }
  // Reopened, the store says the same.
  const std::unique_ptr<FrameStore> reopened = FrameStore::open(temp.config().folder);
  for (const StampedPose& p : trajectory)
    EXPECT_TRUE(reopened->load(p.utime).T_W_C.isApprox(p.T_W_C, 0.0)) << p.utime;
}

TEST_F(MappingSessionTest, MalformedAndTruncatedMessagesAreCounted) {
  std::vector<test::Encoded> messages = stream_.messages();
  std::vector<test::Encoded> bad;
  test::Encoded truncated = messages[2];  // the first RGB-D frame, cut short
  truncated.bytes.resize(truncated.bytes.size() / 2);
  bad.push_back(truncated);
  bad.push_back({"CAMERA_POSE", {1, 2, 3}});
  bad.push_back({"PANOPTIC", std::vector<uint8_t>(64, 0xff)});
  bad.push_back({"CAMERA_RGBD", {}});
  messages.insert(messages.begin() + 3, bad.begin(), bad.end());
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(SessionOptions{}, &mapper);
  feed(&session, messages);
  const SessionStats stats = session.stats();
  EXPECT_EQ(stats.rejected.at("malformed CAMERA_RGBD"), 2);
  EXPECT_EQ(stats.rejected.at("malformed CAMERA_POSE"), 1);
  EXPECT_EQ(stats.rejected.at("malformed PANOPTIC"), 1);
  EXPECT_EQ(stats.frames_integrated, clean_stats_.frames_integrated);
  EXPECT_EQ(test::mapBytes(mapper), clean_);
}

TEST_F(MappingSessionTest, NanPoseAndMismatchedDepthAreRefused) {
  std::vector<test::Encoded> messages = stream_.messages();
  // A NaN pose at a time no frame has, and a frame whose depth disagrees with its intrinsics.
  pose_t nan_msg = toMessage(stream_.poses[0]);
  nan_msg.utime += 1000;
  nan_msg.position[0] = std::numeric_limits<double>::quiet_NaN();
  // Intrinsics of a 640x480 calibration sent with the 160x120 depth image.
  RgbdFrame wrong = stream_.frames[1];
  wrong.utime += 2000;
  wrong.camera.fx = wrong.camera.fy = 525.0;
  wrong.camera.cx = 319.5;
  wrong.camera.cy = 239.5;
  const rgbd_frame_t wrong_msg = toMessage(wrong, ImageEncoding{});
  messages.insert(messages.begin() + 3, test::encodeMessage("CAMERA_POSE", nan_msg));
  messages.insert(messages.begin() + 6, test::encodeMessage("CAMERA_RGBD", wrong_msg));
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(SessionOptions{}, &mapper);
  feed(&session, messages);
  const SessionStats stats = session.stats();
  int64_t pose_rejects = 0, frame_rejects = 0;
  for (const auto& [reason, n] : stats.rejected) {
    if (reason.rfind("bad CAMERA_POSE", 0) == 0) pose_rejects += n;
    if (reason.rfind("bad CAMERA_RGBD", 0) == 0 || reason.rfind("frame:", 0) == 0) {
      frame_rejects += n;
    }
  }
  EXPECT_EQ(pose_rejects, 1);
  EXPECT_EQ(frame_rejects, 1);
  EXPECT_EQ(stats.frames_integrated, clean_stats_.frames_integrated);
  EXPECT_EQ(test::mapBytes(mapper), clean_);
}

TEST_F(MappingSessionTest, UnknownCategoriesBecomeUnlabelled) {
  // Clean reference: the first segment of every mask is unknown (category 0) from the start.
  test::SyntheticStream zeroed = stream_, unknown = stream_;
  for (size_t k = 0; k < stream_.masks.size(); ++k) {
    ASSERT_FALSE(stream_.masks[k].segments.empty());
    zeroed.masks[k].segments[0].category = 0;
    unknown.masks[k].segments[0].category = 9999;
  }
  Mapper reference(test::streamMapperConfig());
  MappingSession reference_session(SessionOptions{}, &reference);
  feed(&reference_session, zeroed.messages());
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(SessionOptions{}, &mapper);
  feed(&session, unknown.messages());
  EXPECT_EQ(session.stats().rejected.at("panoptic segment: unknown category"),
            static_cast<int64_t>(stream_.masks.size()));
  EXPECT_EQ(test::mapBytes(mapper), test::mapBytes(reference));
}

// A converter that lists its segments under other ids than the pixels carry gave a map without
// classes and no word: such masks are counted (and mapped as they are: the pixels vote for no
// segment). The clean stream counts none.
TEST_F(MappingSessionTest, MaskPixelsOfUnlistedSegmentsAreCounted) {
  test::SyntheticStream shifted = stream_;
  for (PanopticFrame& mask : shifted.masks) {
    for (PanopticSegment& segment : mask.segments) segment.id += 100000;
  }
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(SessionOptions{}, &mapper);
  feed(&session, shifted.messages());
  EXPECT_EQ(
      session.stats().rejected.at("panoptic: pixel ids that no segment lists (read as no segment)"),
      static_cast<int64_t>(stream_.masks.size()));
  EXPECT_EQ(
      clean_stats_.rejected.count("panoptic: pixel ids that no segment lists (read as no segment)"),
      0u);
}

TEST_F(MappingSessionTest, FramesWithoutPoseAndAStoppedPoseStream) {
  std::vector<test::Encoded> messages = stream_.messages();
  // After the clean stream the poses stop while frames keep coming: each is refused once
  // the synchroniser has waited long enough (or at the end of the stream).
  const int64_t last = stream_.frames.back().utime;
  for (int k = 1; k <= 5; ++k) {
    RgbdFrame late = stream_.frames[static_cast<size_t>(k)];
    late.utime = last + k * 400000;
    messages.push_back(test::encodeMessage("CAMERA_RGBD", toMessage(late, ImageEncoding{})));
  }
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(SessionOptions{}, &mapper);
  feed(&session, messages);
  const SessionStats stats = session.stats();
  EXPECT_EQ(stats.rejected.at("frame: no pose"), 5);
  EXPECT_EQ(stats.frames_integrated, clean_stats_.frames_integrated);
  EXPECT_EQ(test::mapBytes(mapper), clean_);
}

TEST_F(MappingSessionTest, MaxFramesStopsIntegration) {
  Mapper mapper(test::streamMapperConfig());
  SessionOptions options;
  options.max_frames = 3;
  MappingSession session(options, &mapper);
  feed(&session, stream_.messages());
  EXPECT_TRUE(session.done());
  EXPECT_EQ(session.stats().frames_integrated, 3);
  EXPECT_EQ(mapper.framesIntegrated(), 3);
}

// A loop-closure correction in the stream repairs the map from the frame store: the result is
// the map the same frames give at the corrected poses; without a store it is refused, counted.
TEST_F(MappingSessionTest, AGridShiftMovesEveryPoseItMaps) {
  Mapper unshifted(test::streamMapperConfig());
  MappingSession plain(SessionOptions{}, &unshifted);
  feed(&plain, stream_.messages());
  SessionOptions options;
  options.grid_shift_m = Eigen::Vector3d(0.013, -0.007, 0.005);
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(options, &mapper);
  feed(&session, stream_.messages());
  EXPECT_EQ(session.stats().frames_integrated, static_cast<int64_t>(stream_.frames.size()));
  ASSERT_EQ(mapper.trajectory().size(), unshifted.trajectory().size());
  for (size_t i = 0; i < mapper.trajectory().size(); ++i) {
    const Eigen::Isometry3d& given = unshifted.trajectory()[i].T_W_C;
    const Eigen::Isometry3d& mapped = mapper.trajectory()[i].T_W_C;
    EXPECT_EQ(mapped.linear(), given.linear());
    EXPECT_EQ(mapped.translation(), given.translation() + options.grid_shift_m);
  }
  // The surfaces fall elsewhere in the voxel grid: another map.
  EXPECT_NE(test::mapBytes(mapper), clean_);
}

TEST_F(MappingSessionTest, AGridShiftIsRefusedWithAFrameStoreOrWhenNotFinite) {
  Mapper mapper(test::streamMapperConfig());
  TempStore temp;
  SessionOptions options = temp.options();
  options.grid_shift_m = Eigen::Vector3d(0.01, 0.0, 0.0);
  EXPECT_THROW(MappingSession(options, &mapper), Error);
  options.frame_store = nullptr;
  options.grid_shift_m.y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(MappingSession(options, &mapper), Error);
  options.grid_shift_m = Eigen::Vector3d::Zero();
  options.frame_store = &temp.store;
  EXPECT_NO_THROW(MappingSession(options, &mapper));
}

TEST_F(MappingSessionTest, ACorrectionRepairsTheMapFromTheFrameStore) {
  std::vector<test::Encoded> messages = stream_.messages();
  // The back-end moves keyframe 6 by D; every frame follows (one keyframe corrected).
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  D.linear() = Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  D.translation() = Eigen::Vector3d(0.03, 0.02, 0.0);
  PoseCorrection correction;
  correction.correction_id = 3;
  StampedPose keyframe = stream_.poses[6];
  keyframe.T_W_C = D * keyframe.T_W_C;
  correction.poses.push_back(keyframe);
  messages.push_back(encodeMessage(kChannelPoseCorrection, toMessage(correction)));

  TempStore temp;
  FrameStore& store = temp.store;
  SessionOptions options = temp.options();
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(options, &mapper);
  std::vector<int64_t> progress;
  session.setRepairHook([&progress, &session](int64_t done, int64_t total) {
    progress.push_back(done);
    EXPECT_EQ(total, 12);
    EXPECT_EQ(session.stats().repair_frames_done, done);
  });
  feed(&session, messages);
  const SessionStats stats = session.stats();
  EXPECT_EQ(stats.frames_integrated, 12);
  EXPECT_EQ(store.size(), 12u);
  EXPECT_EQ(stats.corrections_received, 1);
  EXPECT_EQ(stats.corrections_applied, 1);
  EXPECT_EQ(stats.last_correction_id, 3);
  EXPECT_EQ(stats.frames_reintegrated, 12);
  EXPECT_EQ(progress.size(), 12u);
  ASSERT_EQ(stats.repairs.size(), 1u);
  EXPECT_NE(stats.repairs[0].find("correction 3: 1 of 1 poses matched"), std::string::npos)
      << stats.repairs[0];
  EXPECT_EQ(stats.timings.count("frame_store"), 1u);
  EXPECT_TRUE(stats.rejected.empty());

  // The store kept every frame's masks, so the repair mapped the frames again at the
  // corrected poses: the same as remapping a map of the same stream.
  EXPECT_EQ(store.sizeWithPanoptic(), 12u);
  EXPECT_NE(stats.repairs[0].find("12 frames mapped again"), std::string::npos) << stats.repairs[0];
  // With the geometric segments the frames were mapped with: not segmented again.
  EXPECT_NE(stats.repairs[0].find("kept geometric segments of 12 frames"), std::string::npos)
      << stats.repairs[0];
  Mapper clean(test::streamMapperConfig());
  MappingSession plain(SessionOptions{}, &clean);
  feed(&plain, stream_.messages());
  ASSERT_TRUE(clean.remap(mapper.trajectory(), storePanopticLoader(&store)).completed);
  EXPECT_EQ(test::mapBytes(mapper), test::mapBytes(clean));
  for (size_t k = 0; k < mapper.trajectory().size(); ++k) {
    EXPECT_TRUE(mapper.trajectory()[k].T_W_C.isApprox(D * stream_.poses[k].T_W_C, 1e-9)) << k;
  }

  // The same correction again is stale; a newer one naming no mapped frame is refused.
  PoseCorrection stranger = correction;
  stranger.correction_id = 4;
  stranger.poses[0].utime += 50000;  // 50 ms from every frame (frames are further apart)
  const std::vector<test::Encoded> more = {
      encodeMessage(kChannelPoseCorrection, toMessage(correction)),
      encodeMessage(kChannelPoseCorrection, toMessage(stranger)),
      {kChannelPoseCorrection, {1, 2, 3}}};
  const std::string before = test::mapBytes(mapper);
  feed(&session, more);
  const SessionStats after = session.stats();
  EXPECT_EQ(after.corrections_applied, 1);
  EXPECT_EQ(after.rejected.at("correction: not newer than the last one applied"), 1);
  EXPECT_EQ(after.rejected.at("correction: none of its 1 utimes is a mapped frame"), 1);
  EXPECT_EQ(after.rejected.at("malformed PANMAP_POSE_CORRECTION"), 1);
  EXPECT_EQ(test::mapBytes(mapper), before);

  // Corrections that fail their checks are counted by what went wrong, not by the utimes they
  // tripped on: a back-end sending them every second made a counter key each.
  std::vector<test::Encoded> broken;
  for (int k = 0; k < 4; ++k) {
    pose_correction_t msg = toMessage(correction);
    msg.correction_id = 10 + k;
    msg.poses.push_back(msg.poses[0]);
    msg.num_poses = static_cast<int32_t>(msg.poses.size());
    if (k < 2) msg.poses[1].utime -= 1000 * (k + 1);  // utimes not increasing
    if (k == 2) msg.poses[1].utime += 1000, msg.poses[1].position[0] = NAN;  // nested head
    if (k == 3) msg.poses[1].utime = INT64_MAX - k;
    broken.push_back(encodeMessage(kChannelPoseCorrection, msg));
  }
  feed(&session, broken);
  const SessionStats counted = session.stats();
  const std::string bad = "bad " + std::string(kChannelPoseCorrection) + ": ";
  EXPECT_EQ(counted.rejected.at(bad + "pose utimes must increase"), 2);
  EXPECT_EQ(counted.rejected.at(bad + "non-finite value"), 1);
  EXPECT_EQ(counted.rejected.at(bad + "pose: utime out of range"), 1);
  EXPECT_EQ(counted.rejected.size(), after.rejected.size() + 3);
  EXPECT_EQ(test::mapBytes(mapper), before);

  // The map saved and loaded again with its store (a new session): correction 3 is in it, so
  // it is stale there too (applied again, an older correction would undo a repair).
  FrameStore reopened(temp.config());
  EXPECT_EQ(reopened.lastCorrectionId(), std::optional<int64_t>(3));
  SessionOptions again_options;
  again_options.frame_store = &reopened;
  MappingSession again(again_options, &mapper);
  feed(&again, {encodeMessage(kChannelPoseCorrection, toMessage(correction))});
  EXPECT_EQ(again.stats().rejected.at("correction: not newer than the last one applied"), 1);
  EXPECT_EQ(test::mapBytes(mapper), before);

  // Without a frame store the correction is refused and counted.
  Mapper no_store(test::streamMapperConfig());
  MappingSession without(SessionOptions{}, &no_store);
  feed(&without, messages);
  EXPECT_EQ(without.stats().rejected.at("correction: no frame store (panmap-mapper --frame-store)"),
            1);
  EXPECT_EQ(test::mapBytes(no_store), clean_);
}

TEST_F(MappingSessionTest, ACorrectionStampedByAnotherClockStopsNoFrame) {
  // A back-end that stamps its correction with its wall clock (here 10^9 s ahead of the
  // sensor's): the stream's time stood there, and every later frame was refused as waiting too
  // long. And one that moves nothing is applied without a repair.
  const size_t n = stream_.frames.size();
  std::vector<test::Encoded> messages;
  const std::vector<test::Encoded> all = stream_.messages();
  PoseCorrection correction;
  correction.correction_id = 1;
  correction.utime = stream_.frames[5].utime + 1000000000000000;
  correction.poses.push_back(stream_.poses[2]);  // the pose it was mapped with: no move
  for (size_t k = 0; k < n; ++k) {
    if (k <= 5) {
      messages.insert(messages.end(), all.begin() + 3 * k, all.begin() + 3 * k + 3);
    } else {  // from here on the pose comes after its frame (SLAM latency)
      messages.insert(messages.end(), {all[3 * k + 2], all[3 * k + 1], all[3 * k]});
    }
    if (k == 5) messages.push_back(encodeMessage(kChannelPoseCorrection, toMessage(correction)));
  }
  TempStore temp;
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(temp.options(), &mapper);
  feed(&session, messages);
  const SessionStats stats = session.stats();
  EXPECT_EQ(stats.frames_integrated, static_cast<int64_t>(n));
  EXPECT_TRUE(stats.rejected.empty());
  EXPECT_EQ(stats.corrections_applied, 1);
  EXPECT_EQ(stats.frames_reintegrated, 0);
  ASSERT_EQ(stats.repairs.size(), 1u);
  EXPECT_NE(stats.repairs[0].find("correction 1: 1 of 1 poses matched, no camera moved"),
            std::string::npos)
      << stats.repairs[0];
  EXPECT_EQ(test::mapBytes(mapper), clean_);
}

// With background repairs (the live process), a correction in the middle of the stream is
// repaired while the frames after it are mapped: the six frames the correction covered end
// at their corrected poses, the others at theirs, and the map is what mapping the frames
// before the swap again at those poses with their stored masks, then the others, gives,
// whenever the repair happened to be swapped in.
TEST_F(MappingSessionTest, ABackgroundRepairTakesTheFramesMappedMeanwhile) {
  const std::vector<test::Encoded> stream = stream_.messages();
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  D.linear() = Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  D.translation() = Eigen::Vector3d(0.03, 0.02, 0.0);
  PoseCorrection correction;
  correction.correction_id = 3;
  correction.utime = stream_.poses[5].utime;
  StampedPose keyframe = stream_.poses[2];
  keyframe.T_W_C = D * keyframe.T_W_C;
  correction.poses.push_back(keyframe);
  std::vector<test::Encoded> messages(stream.begin(), stream.begin() + 18);  // frames 0-5
  messages.push_back(encodeMessage(kChannelPoseCorrection, toMessage(correction)));
  messages.insert(messages.end(), stream.begin() + 18, stream.end());

  TempStore temp;
  FrameStore& store = temp.store;
  SessionOptions options = temp.options();
  options.background_repair = true;
  Mapper mapper(test::streamMapperConfig());
  MappingSession session(options, &mapper);
  feed(&session, messages);  // flush() waits for the repair
  const SessionStats stats = session.stats();
  EXPECT_FALSE(stats.repair_running);
  EXPECT_EQ(stats.frames_integrated, 12);
  EXPECT_EQ(stats.corrections_applied, 1);
  EXPECT_EQ(stats.corrections_superseded, 0);
  // The six frames the correction covered and those mapped before the repair was swapped in
  // (when that was depends on thread timing; the map does not).
  EXPECT_GE(stats.frames_reintegrated, 6);
  EXPECT_LE(stats.frames_reintegrated, 12);
  ASSERT_EQ(stats.repairs.size(), 1u);
  EXPECT_NE(stats.repairs[0].find("correction 3: 1 of 1 poses matched, "), std::string::npos)
      << stats.repairs[0];
  EXPECT_NE(stats.repairs[0].find(" frames mapped again (6 moved)"), std::string::npos)
      << stats.repairs[0];
  EXPECT_TRUE(stats.rejected.empty());
  for (size_t k = 0; k < 12; ++k) {
    const Eigen::Isometry3d expected = k < 6 ? D * stream_.poses[k].T_W_C : stream_.poses[k].T_W_C;
    EXPECT_TRUE(mapper.trajectory()[k].T_W_C.isApprox(expected, 1e-9)) << k;
  }

  // The same path without a thread: the frames mapped before the swap, mapped again at the poses
  // the repair gave them (its instances and super-points taking the ids of that map's), then
  // the frames after the swap. The ids a repair keeps are those of the map it repairs, which
  // depend on when the swap came; the map from there on does not.
  const size_t swapped = static_cast<size_t>(stats.frames_reintegrated);
  const size_t per_frame = stream.size() / 12;
  Mapper reference(test::streamMapperConfig());
  MappingSession plain(SessionOptions{}, &reference);
  feed(&plain, std::vector<test::Encoded>(stream.begin(), stream.begin() + swapped * per_frame));
  const std::vector<StampedPose> repaired(mapper.trajectory().begin(),
                                          mapper.trajectory().begin() + swapped);
  ASSERT_TRUE(reference.remap(repaired, storePanopticLoader(&store)).completed);
  feed(&plain, std::vector<test::Encoded>(stream.begin() + swapped * per_frame, stream.end()));
  EXPECT_EQ(test::mapBytes(mapper), test::mapBytes(reference)) << swapped << " frames swapped in";
  ASSERT_EQ(mapper.map().numBlocks(), reference.map().numBlocks());
  std::map<std::tuple<int, int, int>, const Block*> blocks;
  for (const auto& b : reference.map().blocks()) {
    blocks[{b->index.x(), b->index.y(), b->index.z()}] = b.get();
  }
  for (const auto& b : mapper.map().blocks()) {
    const Block* other = blocks.at({b->index.x(), b->index.y(), b->index.z()});
    for (int v = 0; v < kBlockVoxels; ++v) {
      ASSERT_EQ(b->voxels[v].sdf_m, other->voxels[v].sdf_m);
      ASSERT_EQ(b->voxels[v].weight, other->voxels[v].weight);
    }
  }
}

// A rejection is counted by what was wrong, not by the message that was: a log whose every
// frame has the same bad intrinsics gives one reason that names the fault.
TEST(MappingSession, RejectionsAreCountedByTheirFault) {
  EXPECT_EQ(reasonOf("rgbd frame 12: principal point (3200, 2400) lies outside the 640x480 "
                     "depth image"),
            "principal point (3200, 2400) lies outside the 640x480 depth image");
  EXPECT_EQ(reasonOf("rgbd frame 13: intrinsics: fx must be > 0"), "intrinsics: fx must be > 0");
  EXPECT_EQ(reasonOf("pose: utime out of range"), "pose");
  EXPECT_EQ(reasonOf("no pose"), "no pose");
  EXPECT_EQ(reasonOf("pose 5:"), "pose 5");
  // A full disk under the frame store gave each frame a reason of its own (31 in one run).
  EXPECT_EQ(storeFailure("cannot write s/frames/300000.depth.zst.partial: No space left on device"),
            "frame store: write failed (No space left on device); the frame is mapped, a repair "
            "cannot move it");
  EXPECT_EQ(
      storeFailure("cannot write s/frames/333333.depth.zst.partial: No space left on device"),
      storeFailure("cannot write s/frames/300000.depth.zst.partial: No space left on device"));
}

}  // namespace
}  // namespace panmap
