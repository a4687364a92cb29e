#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "panmap/core/frame.h"
#include "panmap/core/image.h"
#include "panmap/mapper/mapper.h"

namespace panmap {

/// Loads a list of frames in order on a thread of its own, a few ahead of the one that uses
/// them: a repair decodes the next stored frame while it integrates this one.
class FramePrefetcher {
 public:
  /// @param load called on the prefetcher's thread only, once per utime, in order
  /// @param utimes the frames to load, in the order next() gives them
  /// @param ahead frames loaded and not yet taken at most (>= 1)
  FramePrefetcher(FrameLoader load, std::vector<int64_t> utimes, size_t ahead = 2);
  /// Loads frames with their segmentations (for a remap); next() gives them back.
  /// @param load called on the prefetcher's thread only, once per utime, in order
  FramePrefetcher(PanopticFrameLoader load, std::vector<int64_t> utimes, size_t ahead = 2);
  /// Stops loading (a load under way finishes first) and joins the thread.
  ~FramePrefetcher();
  FramePrefetcher(const FramePrefetcher&) = delete;
  FramePrefetcher& operator=(const FramePrefetcher&) = delete;

  /// The next frame of the list; rethrows what the loader threw for it (nothing is loaded
  /// after a failure). Throws Error when every frame has been taken or one before failed.
  /// @param labels its pixel labels (empty from a PanopticFrameLoader)
  /// @param panoptic if not null, its segmentation (empty from a FrameLoader)
  /// @param kept if not null, its kept geometric segments (empty when none)
  /// @return whether it has a segmentation
  bool next(RgbdFrame* frame, LabelImage* labels, PanopticFrame* panoptic = nullptr,
            GeometricSegments* kept = nullptr);

 private:
  struct Loaded {
    RgbdFrame frame;
    LabelImage labels;
    PanopticFrame panoptic;
    GeometricSegments kept;
    bool has_panoptic = false;
    std::exception_ptr error;
  };
  FramePrefetcher(std::function<void(int64_t, Loaded*)> load, std::vector<int64_t> utimes,
                  size_t ahead);
  void work();

  std::function<void(int64_t, Loaded*)> load_;
  std::vector<int64_t> utimes_;
  size_t ahead_;
  size_t taken_ = 0;
  bool failed_ = false;
  std::mutex mutex_;  // guards what follows
  std::condition_variable cv_;
  std::deque<Loaded> ready_;
  bool stop_ = false;
  std::thread thread_;  // last: starts once the rest is set up
};

}  // namespace panmap
