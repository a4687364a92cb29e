#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "panmap/core/thread_pool.h"
#include "panmap/loop/frame_store.h"
#include "panmap/loop/map_repair.h"
#include "panmap/loop/occupancy_rebuild.h"
#include "panmap/loop/pose_correction.h"
#include "panmap/mapper/mapper.h"

namespace panmap {

/// A loop closure's repair (docs/LOOP_CLOSURE.md) on a thread of its own, while the mapping
/// thread keeps integrating frames: the repair re-integrates (or, with the segmentations
/// stored, maps again) the frames the map held when the correction came, at their corrected
/// poses, then every frame integrated since, at the pose it was mapped with; once it has
/// caught up, poll() swaps the repaired map in between two frames. Before it maps the frames
/// again, it runs over them for early swaps, each of which poll() makes as soon as its pass has
/// caught up: first the occupancy tree alone (MapRepairConfig::occupancy_first), then a
/// re-integrated map (reintegrate_first).
/// A newer correction abandons a running repair and starts again from the map (superseded).
///
/// Threads: every member function is called from the mapping thread (the one that calls
/// Mapper::integrate); the repair's thread only loads frames and builds a MapRebuild with its
/// own thread pool, and never touches the mapper.
class BackgroundRepair {
 public:
  /// @param mapper the live map (not owned; must outlive this)
  /// @param load gives each frame back by its utime; it is called on the repair's thread
  /// @param store if not null, where the corrected poses are recorded when a repair commits
  /// @param panoptic_load if given (and config.reassociate), gives each frame back with its
  ///        segmentation, and a repair started while `store` holds segmentations maps the
  ///        frames again (Mapper::remap) instead of re-integrating them; called on the
  ///        repair's thread
  /// @param holds_segmentations if given, says at start() whether the store holds
  ///        segmentations, frames still on their way to it included (a store written by a
  ///        thread of its own lags behind); else the store's own count decides
  BackgroundRepair(Mapper* mapper, FrameLoader load, FrameStore* store = nullptr,
                   const MapRepairConfig& config = {}, PanopticFrameLoader panoptic_load = {},
                   std::function<bool()> holds_segmentations = {});
  /// Loads the frames from `store` (thread-safe, with their segmentations) and records the
  /// corrected poses there.
  BackgroundRepair(Mapper* mapper, FrameStore* store, const MapRepairConfig& config = {});
  /// Abandons a running repair (the map stays as it is).
  ~BackgroundRepair();
  BackgroundRepair(const BackgroundRepair&) = delete;
  BackgroundRepair& operator=(const BackgroundRepair&) = delete;

  /// Starts the repair for `correction` from the map as it is now, abandoning a running one
  /// first (counted in superseded()). Throws Error like repairMap(), leaving a running repair
  /// alone, when the correction is invalid or none of its utimes is a mapped frame.
  /// A correction that moves no camera (negligible()) starts nothing while no repair runs: its
  /// result comes back at once with nothing_moved set.
  /// @return how the correction matched the map (reintegration is filled by poll())
  MapRepairResult start(const PoseCorrection& correction);
  /// Call after each frame the mapper integrated while running(): the repair takes it too.
  void frameIntegrated();
  /// Between two frames: when the running repair is at most kFramesLeftToCommit frames behind
  /// the map, re-integrates those here, swaps the repaired map in and returns what it did; when it
  /// failed (a frame could not be loaded), returns that with reintegration.completed false and
  /// `failure` set, the map unchanged. Else nothing.
  std::optional<MapRepairResult> poll();
  /// Waits until the running repair has caught up, then as poll() (end of a stream).
  std::optional<MapRepairResult> finish();
  /// Abandons the running repair, if any; the map stays as it is.
  void cancel();

  /// A repair is running (started and not yet returned by poll() or finish()).
  bool running() const { return worker_.joinable(); }
  /// Frames the running (or last) repair has re-integrated, and the frames it has to.
  int64_t framesDone() const;
  int64_t framesTotal() const;
  /// Repairs abandoned for a newer correction.
  int64_t superseded() const { return superseded_; }
  /// poll() swaps the repair in once it is this many frames behind the map or fewer, and
  /// re-integrates them itself (a few frames' delay on the mapping thread): frames keep coming,
  /// so the repair's thread alone is never quite done when asked.
  static constexpr size_t kFramesLeftToCommit = 2;

 private:
  void work();
  void stopWorker();
  MapRepairResult commit();
  /// Loads one frame and adds it to the rebuild at the job's pose; throws Error.
  void reintegrate(const StampedPose& job, RgbdFrame* frame, LabelImage* labels,
                   PanopticFrame* panoptic, GeometricSegments* kept);
  /// What an early pass builds.
  enum class EarlyStage { kOccupancy, kMap };
  /// The early passes: each stage's jobs into occupancy_ or early_map_, until poll() takes the
  /// last. Returns false when the worker must return (stopped or failed).
  bool earlyPass();
  /// One stage of it, until poll() takes it (true) or the worker must return (false).
  bool earlyStage(EarlyStage stage);
  /// Adds a frame loaded with its pixel labels to the stage's pass; throws Error.
  void addEarly(EarlyStage stage, const StampedPose& job, const RgbdFrame& frame,
                const LabelImage& labels);
  /// With mutex_ held by `lock`: when the early stage is at most kFramesLeftToCommit frames
  /// behind, waits for the worker to finish the frame it is on, adds the rest itself, swaps the
  /// tree or the re-integrated map into the mapper and lets the worker go on to the next stage
  /// or to map the frames again.
  void takeEarlyIfReady(std::unique_lock<std::mutex>* lock);
  /// Records the corrected poses of the frames that moved in the store (once per repair).
  void recordPoses();
  /// Throws Error naming both utimes when `frame` is not the job's frame.
  static void checkFrameOf(const StampedPose& job, const RgbdFrame& frame);
  /// Adds a loaded frame at the job's pose; throws Error when it is another frame.
  void addLoaded(const StampedPose& job, const RgbdFrame& frame, const LabelImage& labels,
                 const PanopticFrame* panoptic, const GeometricSegments* kept);

  Mapper* mapper_;
  FrameLoader load_;
  FrameStore* store_;
  MapRepairConfig config_;
  PanopticFrameLoader panoptic_load_;
  std::function<bool()> holds_segmentations_;
  ThreadPool pool_{1};  // the repair's thread integrates alone: the mapper has the others

  // Set by start() on the mapping thread, read by it only, except rebuild_ (the worker's).
  MapRepairResult result_;
  CorrectedTrajectory corrected_;
  std::unique_ptr<MapRebuild> rebuild_;
  bool remap_ = false;  // the running repair maps the frames again
  // The early passes (occupancy_first, then reintegrate_first): the worker's until it waits
  // with every job of its stage done.
  std::unique_ptr<OccupancyRebuild> occupancy_;
  std::unique_ptr<MapRebuild> early_map_;
  double occupancy_swapped_s_ = -1.0;
  double map_swapped_s_ = -1.0;
  size_t map_swapped_rejoined_ = 0;
  double map_swapped_rejoin_s_ = 0.0;
  bool poses_recorded_ = false;
  std::chrono::steady_clock::time_point started_;
  size_t blocks_before_ = 0;
  int64_t superseded_ = 0;

  std::thread worker_;
  mutable std::mutex mutex_;  // guards what follows
  std::condition_variable cv_;
  std::vector<StampedPose> jobs_;  // frames to re-integrate, in order, with their poses
  size_t next_ = 0;                // jobs_ done by the worker
  bool early_pass_ = false;        // the worker runs the early pass (until poll() takes it)
  bool early_handover_ = false;    // poll() takes the early pass over: the worker stops at once
  size_t early_next_ = 0;          // jobs_ in the early pass
  bool idle_ = false;              // the worker waits for a job
  bool stop_ = false;              // the worker must return
  std::string failure_;            // why the worker gave up
  // Which early pass runs: the tree's first, then the re-integrated map's.
  EarlyStage early_stage_ = EarlyStage::kOccupancy;
};

}  // namespace panmap
