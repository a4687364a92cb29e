// Matching frames, poses and masks as they stream in: the timings a robot's camera, SLAM and
// network produce (a network slower than the camera, masks stamped a few ms off, late or
// reordered frames), each with exact counts.
#include <gtest/gtest.h>

#include <vector>

#include "panmap/core/error.h"
#include "panmap/mapper/frame_sync.h"

namespace panmap {
namespace {

constexpr int64_t kMs = 1000;

RgbdFrame frameAt(int64_t utime) {
  RgbdFrame f;
  f.utime = utime;
  return f;
}

StampedPose poseAt(int64_t utime) {
  StampedPose p;
  p.utime = utime;
  p.T_W_C.translation().x() = static_cast<double>(utime) * 1e-6;
  return p;
}

PanopticFrame maskAt(int64_t utime, int64_t frame_id = 0) {
  PanopticFrame m;
  m.utime = utime;
  m.frame_id = frame_id;
  return m;
}

// Frames at 0, 100, ... ms with their poses.
void addFrames(FrameSynchronizer* sync, int n) {
  for (int k = 0; k < n; ++k) {
    sync->addPose(poseAt(100 * kMs * k));
    sync->addFrame(frameAt(100 * kMs * k));
  }
}

TEST(FrameSync, AMaskAFewMillisecondsOffGoesWithItsFrame) {
  FrameSynchronizer sync{SyncConfig{}};
  addFrames(&sync, 2);
  sync.addPanoptic(maskAt(3 * kMs, 7));           // 3 ms after frame 0: within 5 ms
  sync.addPanoptic(maskAt(100 * kMs - 7 * kMs));  // 7 ms before frame 1: not
  std::vector<SyncedFrame> out = sync.popReady(100 * kMs);
  ASSERT_EQ(out.size(), 1u);
  ASSERT_TRUE(out[0].panoptic.has_value());
  EXPECT_EQ(out[0].panoptic->utime, 0);  // the frame's utime from here on
  EXPECT_EQ(out[0].panoptic->frame_id, 7);
  EXPECT_EQ(sync.stats().panoptic_time_offset, 1);
  // Frame 1 waits for a mask within 5 ms until wait_us has passed, then goes without.
  EXPECT_TRUE(sync.popReady(600 * kMs).empty());  // waited exactly 0.5 s: not yet
  out = sync.popReady(601 * kMs);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FALSE(out[0].panoptic.has_value());
  EXPECT_EQ(sync.stats().geometry_only, 1);
  EXPECT_EQ(sync.stats().unmatched_panoptic, 1);
  EXPECT_EQ(sync.stats().last_unmatched_gap_us, 7 * kMs);

  // Tolerance 0: only the exact utime matches.
  SyncConfig exact;
  exact.mask_tolerance_us = 0;
  FrameSynchronizer strict(exact);
  addFrames(&strict, 1);
  strict.addPanoptic(maskAt(1));
  out = strict.popReady(1000 * kMs);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FALSE(out[0].panoptic.has_value());
  EXPECT_EQ(strict.stats().unmatched_panoptic, 1);
}

TEST(FrameSync, ALaterFramesMaskEndsTheWaitOfFramesTheNetworkSkipped) {
  // A network that segments every third frame: frames 1 and 2 never get a mask.
  FrameSynchronizer sync{SyncConfig{}};
  addFrames(&sync, 4);
  sync.addPanoptic(maskAt(0));
  std::vector<SyncedFrame> out = sync.popReady(300 * kMs);
  ASSERT_EQ(out.size(), 1u);  // frame 0; frames 1-3 wait for masks
  sync.addPanoptic(maskAt(300 * kMs));
  out = sync.popReady(300 * kMs);  // no time has passed: the mask of frame 3 says enough
  ASSERT_EQ(out.size(), 3u);
  EXPECT_FALSE(out[0].panoptic.has_value());
  EXPECT_FALSE(out[1].panoptic.has_value());
  EXPECT_TRUE(out[2].panoptic.has_value());
  EXPECT_EQ(sync.stats().geometry_only, 2);
  EXPECT_EQ(sync.stats().geometry_only_queue_full, 0);
  EXPECT_EQ(sync.stats().unmatched_panoptic, 0);

  // A network that may answer out of order: the frames wait out wait_us instead.
  SyncConfig unordered;
  unordered.masks_in_order = false;
  FrameSynchronizer patient(unordered);
  addFrames(&patient, 4);
  patient.addPanoptic(maskAt(300 * kMs));
  EXPECT_TRUE(patient.popReady(300 * kMs).empty());
  patient.addPanoptic(maskAt(0));  // late, but before its frame timed out
  out = patient.popReady(300 * kMs);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].panoptic.has_value());
  EXPECT_EQ(patient.popReady(701 * kMs).size(), 3u);  // 1 and 2 after 0.5 s, then 3
  EXPECT_EQ(patient.stats().geometry_only, 2);
}

TEST(FrameSync, AFullQueueSendsTheOldestFrameOnWithoutItsMask) {
  // A 60 Hz camera with a network that never answers in time: nothing is dropped.
  SyncConfig config;
  config.max_queue = 3;
  FrameSynchronizer sync(config);
  std::vector<SyncedFrame> out;
  for (int k = 0; k < 10; ++k) {
    sync.addPose(poseAt(16 * kMs * k));
    sync.addFrame(frameAt(16 * kMs * k));
    for (SyncedFrame& f : sync.popReady(16 * kMs * k)) out.push_back(std::move(f));
  }
  ASSERT_EQ(out.size(), 7u);  // 10 frames, 3 still waiting
  for (size_t k = 0; k < out.size(); ++k) EXPECT_EQ(out[k].frame.utime, 16 * kMs * int64_t(k));
  EXPECT_EQ(sync.stats().geometry_only_queue_full, 7);
  EXPECT_EQ(sync.stats().dropped_queue_full, 0);
  EXPECT_EQ(sync.flush().size(), 3u);

  // Frames without a pose under the same pressure are dropped, counted: two over the queue.
  FrameSynchronizer posed(config);
  for (int k = 0; k < 5; ++k) posed.addFrame(frameAt(16 * kMs * k));
  EXPECT_TRUE(posed.popReady(64 * kMs).empty());
  EXPECT_EQ(posed.stats().dropped_queue_full, 2);
}

TEST(FrameSync, AFrameArrivingOutOfOrderKeepsItsMask) {
  // Frame 1's message is 200 ms late; its mask came on time.
  FrameSynchronizer sync{SyncConfig{}};
  for (int k : {0, 2, 3}) sync.addPose(poseAt(100 * kMs * k));
  sync.addPose(poseAt(100 * kMs));
  sync.addFrame(frameAt(0));
  sync.addPanoptic(maskAt(0));
  EXPECT_EQ(sync.popReady(0).size(), 1u);
  sync.addPanoptic(maskAt(100 * kMs));
  sync.addFrame(frameAt(200 * kMs));
  sync.addFrame(frameAt(300 * kMs));
  EXPECT_TRUE(sync.popReady(300 * kMs).empty());  // frame 2 waits for its mask
  sync.addFrame(frameAt(100 * kMs));
  const std::vector<SyncedFrame> out = sync.popReady(300 * kMs);
  ASSERT_GE(out.size(), 1u);
  EXPECT_EQ(out[0].frame.utime, 100 * kMs);
  EXPECT_TRUE(out[0].panoptic.has_value());
  EXPECT_EQ(sync.stats().unmatched_panoptic, 0);
  EXPECT_EQ(sync.stats().out_of_order_frames, 0);
}

TEST(FrameSync, AMaskAfterItsFrameWasMappedIsLate) {
  SyncConfig config;
  config.masks_in_order = false;
  FrameSynchronizer sync(config);
  addFrames(&sync, 1);
  ASSERT_EQ(sync.popReady(600 * kMs).size(), 1u);  // waited 0.5 s, mapped without
  sync.addPanoptic(maskAt(2 * kMs));               // 2 ms off the mapped frame
  EXPECT_EQ(sync.stats().late_panoptic, 1);
  sync.addPanoptic(maskAt(50 * kMs));  // nearer no mapped frame: may still find one
  EXPECT_EQ(sync.stats().late_panoptic, 1);
}

// Frames the caller drops (a full input queue) or refuses (mapped before a resume point) never
// reach the synchroniser, their masks do: counted as masks of skipped frames, not as masks that
// matched no frame (whose warning blamed the masks' timestamps, once per dropped frame).
TEST(FrameSync, MasksOfSkippedFramesAreNoTimingFault) {
  FrameSynchronizer sync{SyncConfig{}};
  sync.addPanoptic(maskAt(100 * kMs + 2 * kMs));  // held before its frame is skipped
  sync.skipFrame(100 * kMs);
  sync.skipFrame(200 * kMs);
  sync.addPanoptic(maskAt(200 * kMs));  // arrives after
  sync.addPose(poseAt(300 * kMs));
  sync.addFrame(frameAt(300 * kMs));
  sync.skipFrame(303 * kMs);  // a waiting frame nearer its mask keeps it
  sync.addPanoptic(maskAt(301 * kMs, 9));
  sync.addPanoptic(maskAt(400 * kMs));  // a mask whose frame never came at all
  std::vector<SyncedFrame> out = sync.popReady(300 * kMs);
  ASSERT_EQ(out.size(), 1u);
  ASSERT_TRUE(out[0].panoptic.has_value());
  EXPECT_EQ(out[0].panoptic->frame_id, 9);
  EXPECT_EQ(sync.stats().panoptic_of_skipped_frames, 2);
  sync.flush();
  EXPECT_EQ(sync.stats().unmatched_panoptic, 1);
  EXPECT_EQ(sync.stats().panoptic_of_skipped_frames, 2);
}

TEST(FrameSync, ConfigChecksNameTheField) {
  SyncConfig bad;
  bad.mask_tolerance_us = -1;
  try {
    FrameSynchronizer sync(bad);
    FAIL() << "a negative tolerance was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mask_tolerance_us"), std::string::npos);
  }
}

}  // namespace
}  // namespace panmap
