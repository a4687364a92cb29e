#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/value_spread.h"
#include "panmap/lcm/channels.h"
#include "panmap/loop/background_repair.h"
#include "panmap/loop/frame_store.h"
#include "panmap/loop/frame_store_writer.h"
#include "panmap/loop/map_repair.h"
#include "panmap/mapper/frame_sync.h"
#include "panmap/mapper/mapper.h"

namespace panmap {

/// Input channels and synchronisation of a mapping run (offline or live).
struct SessionOptions {
  std::string channel_rgbd = "CAMERA_RGBD";
  std::string channel_pose = "CAMERA_POSE";
  std::string channel_panoptic = "PANOPTIC";
  /// Loop-closure corrections (pose_correction_t); they repair the map from frame_store.
  std::string channel_correction = kChannelPoseCorrection;
  SyncConfig sync;
  /// Where every integrated frame is kept for loop-closure repairs (not owned; written by a
  /// thread of the session's own, FrameStoreWriter); null: no store, and corrections are
  /// refused (counted).
  FrameStore* frame_store = nullptr;
  MapRepairConfig repair;
  /// Repairs run on a thread of their own while frames keep being integrated (the live
  /// process); false: each repair runs to its end before the next frame (offline runs, whose
  /// maps must not depend on thread timing).
  bool background_repair = false;
  int64_t max_frames = 0;  ///< stop integrating after this many frames (0 = all)
  /// Frames at or before this utime are refused (counted): a resumed map already holds them.
  int64_t resume_after_utime = INT64_MIN;
  /// A diagnostic: every pose is moved by this translation, metres, before it is mapped, so
  /// the voxel grid falls elsewhere on the same surfaces (outputs are in the moved frame). A
  /// method whose outputs change with it depends on where voxel boundaries fall: the noise
  /// floor of a comparison (scripts/bench/noise_floor.py). Not with a frame store.
  Eigen::Vector3d grid_shift_m = Eigen::Vector3d::Zero();
};

/// Median and 95th percentile of a stage's per-frame time.
struct StageTiming {
  double median_ms = 0.0;
  double p95_ms = 0.0;
  double last_ms = 0.0;  ///< the most recent frame
};

/// How far pose refinement moved the poses it was given, over the frames it tracked: the
/// camera centre's displacement and the rotation angle between given and refined pose.
struct PoseRefinementStats {
  int64_t frames = 0;  ///< frames tracked against the map
  ValueSpread moved_m;
  ValueSpread turned_deg;
};

/// What a session has done so far.
struct SessionStats {
  int64_t messages = 0;           ///< messages on the three input channels
  int64_t frames_received = 0;    ///< RGB-D messages that decoded
  int64_t frames_integrated = 0;  ///< frames fused into the map
  int64_t last_frame_utime = 0;   ///< utime of the newest integrated frame
  /// With resume_after_utime: a frame at exactly that utime came (the log is the map's own).
  bool resume_point_seen = false;
  std::map<std::string, int64_t> rejected;  ///< reason -> frames (or messages) refused
  SyncStats sync;
  std::map<std::string, StageTiming> timings;  ///< by stage name
  /// What tracking did to the given poses (MapperConfig::tracking_mode): a good SLAM system's
  /// poses moved by centimetres are a sign that refinement hurts (an uncalibrated depth sensor,
  /// docs/MAPPING.md).
  PoseRefinementStats refinement;
  int64_t corrections_received = 0;    ///< pose_correction_t messages that decoded
  int64_t corrections_applied = 0;     ///< of those, repairs that completed
  int64_t last_correction_id = 0;      ///< correction_id of the newest repair
  int64_t frames_reintegrated = 0;     ///< frames re-integrated by all repairs
  int64_t repair_frames_done = 0;      ///< progress of the repair running or last run
  int64_t repair_frames_total = 0;     ///< frames it re-integrates
  double last_repair_s = 0.0;          ///< wall time of the last completed repair
  bool repair_running = false;         ///< a background repair is under way
  int64_t corrections_superseded = 0;  ///< background repairs a newer one abandoned
  std::vector<std::string> repairs;    ///< describe() of every repair, in order
};

/// One mapping run over a stream of LCM messages, the same for the offline reader and the
/// live process so that both treat input identically: decodes each message (counting
/// malformed ones), sanitises it, synchronises frames with poses and masks, integrates
/// the ready frames (keeping each in the frame store, if any), and repairs the map when a
/// loop-closure correction arrives (SessionOptions::background_repair: on its own thread while
/// frames keep coming, else before the next frame). Bad input
/// is refused with a counted reason and never touches the map. Not thread-safe: one thread feeds
/// it.
class MappingSession {
 public:
  /// Called after each integrated frame (e.g. to update the occupancy tree).
  using FrameHook = std::function<void(const SyncedFrame&, const FrameStats&)>;

  /// @param mapper the map to extend (not owned; must outlive the session)
  MappingSession(const SessionOptions& options, Mapper* mapper);

  /// Handles one message. Messages on other channels are ignored (returns false).
  /// @param now_utime stream time for the synchroniser's waits; negative: the newest message
  ///        utime seen so far
  bool handle(const std::string& channel, const void* data, size_t size, int64_t now_utime = -1);
  /// Counts a message dropped before it reached the session (e.g. a full queue).
  void countDropped(const std::string& reason, int64_t n = 1);
  /// Maps what is still waiting at the end of the stream (frames with a pose), rejects the rest,
  /// and waits for a background repair to finish.
  void flush();
  /// Says the frame at `utime` was dropped before it reached the session (a full input queue):
  /// its mask is counted with it, not as a mask that matched no frame.
  void skipFrame(int64_t utime) { sync_.skipFrame(utime); }
  /// Swaps in a background repair that has caught up with the map (also done after every
  /// message; call it when no message comes for a while).
  void poll();
  /// True once max_frames frames are integrated.
  bool done() const { return done_; }
  /// Counters and stage timings so far.
  SessionStats stats() const;
  /// Called after every integrated frame.
  void setFrameHook(FrameHook hook) { hook_ = std::move(hook); }
  /// Called after every frame a repair re-integrates with (frames done, frames in all), e.g.
  /// to publish the status (stats() then shows the same progress); a background repair calls
  /// it once, when it starts (0, frames), and its progress shows in stats() meanwhile.
  void setRepairHook(std::function<void(int64_t done, int64_t total)> hook) {
    repair_hook_ = std::move(hook);
  }

 private:
  void integrate(std::vector<SyncedFrame> ready);
  void sanitise(PanopticFrame* panoptic);
  void repair(const PoseCorrection& correction);
  void recordRepair(const MapRepairResult& result);
  void countRepairError(const std::string& what);
  void countStoreErrors();
  // Records in the frame store the poses of the `count` frames before the newest that the
  // depth check took back to their given poses.
  void recordRevertedPoses(int count);

  SessionOptions options_;
  Mapper* mapper_;
  FrameSynchronizer sync_;
  FrameHook hook_;
  std::function<void(int64_t, int64_t)> repair_hook_;
  SessionStats stats_;
  std::map<std::string, std::vector<double>> times_ms_;
  // Per tracked frame: how far refinement moved the given pose (metres, degrees).
  std::vector<double> refinement_moved_m_, refinement_turned_deg_;
  int64_t newest_utime_ = INT64_MIN;
  /// The newest correction the frame store holds from an earlier session (--load, --resume).
  std::optional<int64_t> applied_before_;
  bool done_ = false;
  std::unique_ptr<FrameStoreWriter> writer_;      // with a frame store: writes it off this thread
  bool stored_segmentation_ = false;              // a frame went to the store with its masks
  std::unique_ptr<BackgroundRepair> background_;  // with background_repair, once needed
  int64_t running_correction_id_ = 0;             // of the background repair under way
};

/// Median / p95 / last of a list of times.
StageTiming summariseTimes(std::vector<double> times_ms);

/// An error message's counted reason: its text up to the first ':' ("pose", "extent"), or,
/// when that names one message by its number ("rgbd frame 12: principal point ..."), the text
/// after it, so that every frame with the same fault counts under one reason that says it.
std::string reasonOf(const std::string& what);

/// The counted reason of a frame store write that failed: the cause (the text after the last
/// ": ", e.g. "No space left on device") without the file, which names one frame.
std::string storeFailure(const std::string& what);

/// One line per way the frames and masks of a session failed to meet (frames mapped without
/// a mask while masks do come, masks that matched no frame or came late, frames sent on by a
/// full queue), naming the sync setting that governs it; empty when none did. For the
/// status channel's warnings and the end of an offline run.
std::vector<std::string> syncWarnings(const SessionStats& stats, const SyncConfig& config);

}  // namespace panmap
