#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/frame.h"
#include "panmap/core/pose.h"

namespace panmap {

/// How frames, poses and panoptic masks are matched by utime.
struct SyncConfig {
  /// A pose this close to the frame's utime is used as is (microseconds).
  int64_t pose_tolerance_us = 5000;
  /// Poses bracketing the frame no more than this far apart are interpolated (microseconds).
  int64_t max_pose_gap_us = 200000;
  /// A panoptic mask goes with the waiting frame nearest its utime within this (microseconds):
  /// a network that stamps its output through another clock or a float is a few off.
  int64_t mask_tolerance_us = 5000;
  /// How long a frame waits for its panoptic mask before it is mapped geometry-only, and for a
  /// pose before it is rejected (microseconds of stream time: the newest utime received).
  int64_t wait_us = 500000;
  /// The network segments frames in order: once a mask of a later frame has arrived, a frame
  /// still without one will not get one and is mapped geometry-only at once (a network slower
  /// than the camera skips frames; without this each skipped frame waited wait_us).
  bool masks_in_order = true;
  /// Frames waiting at most. Beyond it the oldest goes on without its mask when it has a pose
  /// (counted as geometry-only), and is dropped (counted) when it has none.
  size_t max_queue = 30;
  /// Throws Error naming the bad field.
  void check() const;
};

/// A frame with everything needed to map it.
struct SyncedFrame {
  RgbdFrame frame;
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  PoseSource pose_source = PoseSource::kUnknown;
  std::optional<PanopticFrame> panoptic;  ///< empty: map geometry-only
  bool pose_interpolated = false;
};

/// Counters of what the synchroniser did, with reasons.
struct SyncStats {
  int64_t frames_in = 0;
  int64_t frames_out = 0;
  int64_t dropped_queue_full = 0;  ///< oldest frames dropped because the queue was full
  int64_t rejected_no_pose = 0;    ///< no pose arrived in time
  /// Of those, frames with poses before and after them, too far apart to interpolate
  /// (max_pose_gap_us) and none within pose_tolerance_us: a SLAM that sends keyframes only.
  int64_t rejected_pose_gap = 0;
  int64_t last_pose_gap_us = 0;  ///< the gap between those poses for the last such frame
  int64_t geometry_only = 0;     ///< mapped without a panoptic mask
  /// Of those, released before wait_us because the queue was full.
  int64_t geometry_only_queue_full = 0;
  int64_t unmatched_panoptic = 0;   ///< masks whose frame never came (or came too late)
  int64_t repeated_frames = 0;      ///< frames with the utime of a queued or mapped frame
  int64_t out_of_order_frames = 0;  ///< frames older than one already mapped or refused
  int64_t repeated_poses = 0;       ///< poses with the utime of a held pose (the first kept)
  int64_t repeated_panoptic = 0;    ///< masks with the utime of a held mask (the first kept)
  int64_t late_panoptic = 0;        ///< masks arriving after their frame was mapped or refused
  /// Masks matched to a frame whose utime differs from theirs (within mask_tolerance_us).
  int64_t panoptic_time_offset = 0;
  /// Masks of frames the caller skipped (skipFrame(): dropped behind, or mapped before a
  /// resume point): not a timing fault, so not among unmatched_panoptic.
  int64_t panoptic_of_skipped_frames = 0;
  /// How far the last unmatched mask's utime was from the nearest frame's (-1: no frame yet).
  int64_t last_unmatched_gap_us = -1;
};

/// Matches RGB-D frames with poses (exact, nearest within a tolerance, or interpolated) and
/// panoptic masks (nearest within a tolerance) as they stream in, in any interleaving.
class FrameSynchronizer {
 public:
  /// Throws Error when the config is invalid.
  explicit FrameSynchronizer(const SyncConfig& config);

  /// Queues a frame in utime order (popReady() sends the oldest on when full). A frame whose utime
  /// repeats a queued or already handled frame's, or is older than the newest handled frame, is
  /// refused and counted: the map must not depend on duplicated or late messages.
  void addFrame(RgbdFrame frame);
  /// Adds a pose; poses must be finite (the caller validates). A repeated utime keeps the
  /// first pose (counted).
  void addPose(const StampedPose& pose);
  /// Adds a panoptic mask for the frame nearest its utime (within mask_tolerance_us); a
  /// repeated utime keeps the first, a mask whose frame was already handled is dropped (both
  /// counted).
  void addPanoptic(PanopticFrame panoptic);
  /// Says the frame at `utime` will not come (the caller dropped or refused it): its mask,
  /// held or still to come, is dropped and counted as panoptic_of_skipped_frames, not as a mask
  /// that matched no frame (whose warning blamed the masks' timestamps).
  void skipFrame(int64_t utime);

  /// Frames ready at stream time `now_utime` (the newest utime seen, or the wall clock),
  /// oldest first. Frames that waited too long for a pose are rejected and counted.
  std::vector<SyncedFrame> popReady(int64_t now_utime);
  /// Everything still queued at the end of a stream: mapped if it has a pose, else rejected.
  std::vector<SyncedFrame> flush();
  /// What happened so far.
  const SyncStats& stats() const { return stats_; }

 private:
  std::optional<Eigen::Isometry3d> poseAt(int64_t utime, bool final, bool* interpolated,
                                          PoseSource* source) const;
  void prunePoses(int64_t oldest_needed);
  /// Counts a frame refused for want of a pose whose poses around it were too far apart.
  void countPoseGap(int64_t utime);
  /// |utime - the nearest frame's utime| over the handled and the waiting frames; -1: none.
  int64_t nearestFrameGap(int64_t utime) const;
  /// The held mask nearest `utime` within the tolerance, or panoptics_.end().
  std::map<int64_t, PanopticFrame>::iterator maskFor(int64_t utime);
  /// A skipped frame within the mask tolerance of `utime`.
  bool ofSkippedFrame(int64_t utime) const;

  SyncConfig config_;
  std::deque<RgbdFrame> frames_;
  std::map<int64_t, StampedPose> poses_;
  std::map<int64_t, PanopticFrame> panoptics_;
  std::set<int64_t> skipped_;           ///< utimes of skipped frames whose masks may still come
  int64_t newest_handled_ = INT64_MIN;  ///< utime of the newest frame mapped or refused
  int64_t newest_mask_ = INT64_MIN;     ///< utime of the newest mask received
  SyncStats stats_;
};

}  // namespace panmap
