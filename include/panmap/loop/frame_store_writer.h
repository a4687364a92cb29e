#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/frame.h"
#include "panmap/core/image.h"
#include "panmap/loop/frame_store.h"

namespace panmap {

/// Writes frames into a FrameStore on a thread of its own: encoding the PNGs and syncing the
/// files costs more than mapping a frame (docs/LOOP_CLOSURE.md), and the mapping thread should
/// not wait for it. Frames are written in the order they are added; load() of a frame still
/// queued waits until it is written. At most `max_queued` frames wait: add() blocks beyond
/// that, so memory stays bounded when the disk is slower than the camera.
/// Thread-safety: every member function may be called from several threads at once.
class FrameStoreWriter {
 public:
  /// @param store where the frames go (not owned; must outlive the writer)
  /// @param max_queued frames queued and not yet written at most (>= 1)
  explicit FrameStoreWriter(FrameStore* store, size_t max_queued = 8);
  /// Writes what is still queued, then stops.
  ~FrameStoreWriter();
  FrameStoreWriter(const FrameStoreWriter&) = delete;
  FrameStoreWriter& operator=(const FrameStoreWriter&) = delete;

  /// Queues a copy of the frame for FrameStore::add(); a write that fails is reported by
  /// takeErrors(), the store unchanged. Throws Error when the frame's utime is already queued.
  /// @param T_W_C camera-to-world pose (optical frame) it was integrated with
  /// @param labels the super-point label each pixel voted for
  /// @param panoptic the frame's panoptic segmentation, or null
  /// @param geometric its geometric segments (kept with a segmentation only; empty: none)
  void add(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C, const LabelImage& labels,
           const PanopticFrame* panoptic = nullptr, GeometricSegments geometric = {});
  /// Waits until every frame queued so far is written (or has failed).
  void flush();
  /// FrameStore::load(), after waiting for the frame if it is still queued or being written.
  StoredFrame load(int64_t utime);
  /// The errors of failed writes since the last call, one line each (FrameStore::add's).
  std::vector<std::string> takeErrors();
  /// Frames queued or being written now.
  size_t queued() const;
  /// The store written to.
  FrameStore* store() const { return store_; }

 private:
  struct Job {
    RgbdFrame frame;
    Eigen::Isometry3d T_W_C;
    LabelImage labels;
    bool has_panoptic = false;
    PanopticFrame panoptic;
    GeometricSegments geometric;
  };
  void work();

  FrameStore* store_;
  size_t max_queued_;
  mutable std::mutex mutex_;  // guards what follows
  std::condition_variable cv_;
  std::deque<Job> queue_;
  std::set<int64_t> unwritten_;  // utimes queued or being written
  std::vector<std::string> errors_;
  bool stop_ = false;
  std::thread thread_;  // last: starts once the rest is set up
};

}  // namespace panmap
