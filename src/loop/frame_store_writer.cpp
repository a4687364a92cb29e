// FrameStoreWriter: frame store writes off the mapping thread.
#include "panmap/loop/frame_store_writer.h"

#include <utility>

#include "panmap/core/error.h"

namespace panmap {

FrameStoreWriter::FrameStoreWriter(FrameStore* store, size_t max_queued)
    : store_(store), max_queued_(max_queued) {
  if (!store_) throw Error("FrameStoreWriter: no frame store");
  if (max_queued_ < 1) throw Error("FrameStoreWriter: max_queued must be at least 1");
  thread_ = std::thread(&FrameStoreWriter::work, this);
}

FrameStoreWriter::~FrameStoreWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void FrameStoreWriter::add(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                           const LabelImage& labels, const PanopticFrame* panoptic,
                           GeometricSegments geometric) {
  // Copied before the lock: a few MB.
  Job job{frame,
          T_W_C,
          labels,
          panoptic != nullptr,
          panoptic ? *panoptic : PanopticFrame(),
          std::move(geometric)};
  std::unique_lock<std::mutex> lock(mutex_);
  if (unwritten_.count(frame.utime)) {
    throw Error("frame store: frame " + std::to_string(frame.utime) + " is already queued");
  }
  cv_.wait(lock, [this] { return queue_.size() < max_queued_; });
  queue_.push_back(std::move(job));
  unwritten_.insert(frame.utime);
  lock.unlock();
  cv_.notify_all();
}

void FrameStoreWriter::work() {
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, and everything is written
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    cv_.notify_all();  // room in the queue
    std::string error;
    try {
      store_->add(job.frame, job.T_W_C, job.labels, job.has_panoptic ? &job.panoptic : nullptr,
                  job.geometric.ids.empty() ? nullptr : &job.geometric);
    } catch (const std::exception& e) {
      error = e.what();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error.empty()) errors_.push_back(std::move(error));
      unwritten_.erase(job.frame.utime);
    }
    cv_.notify_all();
  }
}

void FrameStoreWriter::flush() {
  std::unique_lock<std::mutex> lock(mutex_);
  cv_.wait(lock, [this] { return unwritten_.empty(); });
}

StoredFrame FrameStoreWriter::load(int64_t utime) {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [this, utime] { return unwritten_.count(utime) == 0; });
  }
  return store_->load(utime);
}

std::vector<std::string> FrameStoreWriter::takeErrors() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> out;
  out.swap(errors_);
  return out;
}

size_t FrameStoreWriter::queued() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return unwritten_.size();
}

}  // namespace panmap
