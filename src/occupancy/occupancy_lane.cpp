#include "panmap/occupancy/occupancy_lane.h"

#include "panmap/core/error.h"

namespace panmap {

OccupancyLane::OccupancyLane(OccupancyMap* map, size_t capacity) : map_(map) {
  if (!map) throw Error("OccupancyLane: no occupancy map");
  if (capacity < 1) throw Error("OccupancyLane: capacity must be >= 1");
  ring_.resize(capacity);
  thread_ = std::thread([this] { run(); });
}

OccupancyLane::~OccupancyLane() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return queued_ == 0; });
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void OccupancyLane::push(const DepthImage& depth, double depth_scale_m, const PinholeCamera& camera,
                         const Eigen::Isometry3d& T_W_C) {
  map_->validate(depth, depth_scale_m, camera, T_W_C);  // reads only the config and grid size
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return queued_ < ring_.size(); });
  // The slot after the queued ones is free: the thread reads only ring_[head_], a queued one.
  Job& job = ring_[(head_ + queued_) % ring_.size()];
  lock.unlock();
  job.depth = depth;
  job.depth_scale_m = depth_scale_m;
  job.camera = camera;
  job.T_W_C = T_W_C;
  lock.lock();
  ++queued_;
  lock.unlock();
  changed_.notify_all();
}

void OccupancyLane::finish() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return queued_ == 0; });
  if (error_) {
    const std::exception_ptr error = error_;
    error_ = nullptr;
    std::rethrow_exception(error);
  }
}

void OccupancyLane::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return stop_ || queued_ > 0; });
    if (queued_ == 0) return;  // stop_ and nothing left
    Job& job = ring_[head_];   // push() writes only the slots after the queued ones
    const bool failed = static_cast<bool>(error_);
    lock.unlock();
    std::exception_ptr error;
    try {
      // After a failure the map is left as it was: the caller learns of it at finish().
      if (!failed) map_->integrate(job.depth, job.depth_scale_m, job.camera, job.T_W_C);
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    if (error) error_ = error;
    head_ = (head_ + 1) % ring_.size();
    --queued_;
    changed_.notify_all();
  }
}

}  // namespace panmap
