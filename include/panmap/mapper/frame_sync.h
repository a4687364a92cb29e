#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
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
  /// How long a frame waits for its panoptic mask before it is mapped geometry-only, and for a
  /// pose before it is rejected (microseconds of stream time).
  int64_t wait_us = 500000;
  /// Frames waiting at most; beyond it the oldest is dropped and counted.
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
  int64_t dropped_queue_full = 0;   ///< oldest frames dropped because the queue was full
  int64_t rejected_no_pose = 0;     ///< no pose arrived in time
  int64_t geometry_only = 0;        ///< mapped without a panoptic mask
  int64_t unmatched_panoptic = 0;   ///< masks whose frame never came (or came too late)
  int64_t repeated_frames = 0;      ///< frames with the utime of a queued or mapped frame
  int64_t out_of_order_frames = 0;  ///< frames older than one already mapped or refused
  int64_t repeated_poses = 0;       ///< poses with the utime of a held pose (the first kept)
  int64_t repeated_panoptic = 0;    ///< masks with the utime of a held mask (the first kept)
  int64_t late_panoptic = 0;        ///< masks arriving after their frame was mapped or refused
};

/// Matches RGB-D frames with poses (exact, nearest within a tolerance, or interpolated) and
/// panoptic masks (exact utime) as they stream in, in any interleaving.
class FrameSynchronizer {
 public:
  /// Throws Error when the config is invalid.
  explicit FrameSynchronizer(const SyncConfig& config);

  /// Queues a frame in utime order (drops the oldest when full). A frame whose utime repeats a
  /// queued or already handled frame's, or is older than the newest handled frame, is refused
  /// and counted: the map must not depend on duplicated or late messages.
  void addFrame(RgbdFrame frame);
  /// Adds a pose; poses must be finite (the caller validates). A repeated utime keeps the
  /// first pose (counted).
  void addPose(const StampedPose& pose);
  /// Adds a panoptic mask for the frame with the same utime; a repeated utime keeps the first,
  /// a mask whose frame was already handled is dropped (both counted).
  void addPanoptic(PanopticFrame panoptic);

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

  SyncConfig config_;
  std::deque<RgbdFrame> frames_;
  std::map<int64_t, StampedPose> poses_;
  std::map<int64_t, PanopticFrame> panoptics_;
  int64_t newest_handled_ = INT64_MIN;  ///< utime of the newest frame mapped or refused
  SyncStats stats_;
};

}  // namespace panmap
