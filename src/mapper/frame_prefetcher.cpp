// FramePrefetcher: stored frames decoded ahead on a thread of their own.
#include "panmap/mapper/frame_prefetcher.h"

#include <string>
#include <utility>

#include "panmap/core/error.h"

namespace panmap {

FramePrefetcher::FramePrefetcher(FrameLoader load, std::vector<int64_t> utimes, size_t ahead)
    : FramePrefetcher(
          load ? std::function<void(int64_t, Loaded*)>(
                     [load](int64_t utime, Loaded* out) { load(utime, &out->frame, &out->labels); })
               : nullptr,
          std::move(utimes), ahead) {}

FramePrefetcher::FramePrefetcher(PanopticFrameLoader load, std::vector<int64_t> utimes,
                                 size_t ahead)
    : FramePrefetcher(
          load ? std::function<void(int64_t, Loaded*)>([load](int64_t utime, Loaded* out) {
            out->has_panoptic = load(utime, &out->frame, &out->panoptic, &out->kept);
          })
               : nullptr,
          std::move(utimes), ahead) {}

FramePrefetcher::FramePrefetcher(std::function<void(int64_t, Loaded*)> load,
                                 std::vector<int64_t> utimes, size_t ahead)
    : load_(std::move(load)), utimes_(std::move(utimes)), ahead_(ahead) {
  if (!load_) throw Error("FramePrefetcher: no frame loader");
  if (ahead_ < 1) throw Error("FramePrefetcher: ahead must be at least 1");
  thread_ = std::thread(&FramePrefetcher::work, this);
}

FramePrefetcher::~FramePrefetcher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void FramePrefetcher::work() {
  for (const int64_t utime : utimes_) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [this] { return stop_ || ready_.size() < ahead_; });
      if (stop_) return;
    }
    Loaded loaded;
    try {
      load_(utime, &loaded);
    } catch (...) {
      loaded.error = std::current_exception();
    }
    const bool failed = static_cast<bool>(loaded.error);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ready_.push_back(std::move(loaded));
    }
    cv_.notify_all();
    if (failed) return;  // next() rethrows it; nothing after a failure is wanted
  }
}

bool FramePrefetcher::next(RgbdFrame* frame, LabelImage* labels, PanopticFrame* panoptic,
                           GeometricSegments* kept) {
  if (taken_ >= utimes_.size()) {
    throw Error("FramePrefetcher: all " + std::to_string(utimes_.size()) + " frames taken");
  }
  if (failed_) throw Error("FramePrefetcher: an earlier frame failed to load");
  Loaded loaded;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [this] { return !ready_.empty(); });
    loaded = std::move(ready_.front());
    ready_.pop_front();
  }
  cv_.notify_all();
  ++taken_;
  if (loaded.error) {
    failed_ = true;
    std::rethrow_exception(loaded.error);
  }
  *frame = std::move(loaded.frame);
  *labels = std::move(loaded.labels);
  if (panoptic) *panoptic = std::move(loaded.panoptic);
  if (kept) *kept = std::move(loaded.kept);
  return loaded.has_panoptic;
}

}  // namespace panmap
