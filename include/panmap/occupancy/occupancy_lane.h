#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/camera.h"
#include "panmap/core/image.h"
#include "panmap/occupancy/occupancy_map.h"

namespace panmap {

/// Integrates depth frames into an OccupancyMap on a thread of its own, in the order they are
/// pushed, up to `capacity` frames behind the caller. A repair that re-integrates stored
/// frames uses it so that the tree's ray casting fills the gaps of the label-TSDF's parallel
/// loops instead of waiting for them frame by frame (docs/LOOP_CLOSURE.md). The map is the
/// one a sequence of OccupancyMap::integrate calls would give, bit for bit.
class OccupancyLane {
 public:
  /// @param map the tree to update (not owned; outlives the lane; touch it only after finish())
  /// @param capacity frames queued at most; push() waits while that many are
  explicit OccupancyLane(OccupancyMap* map, size_t capacity = 4);
  /// Integrates what is still queued, then stops the thread.
  ~OccupancyLane();
  OccupancyLane(const OccupancyLane&) = delete;
  OccupancyLane& operator=(const OccupancyLane&) = delete;

  /// Checks the frame now, throwing the Error OccupancyMap::integrate would (nothing queued),
  /// then queues a copy of its depth image; waits while `capacity` frames are queued.
  void push(const DepthImage& depth, double depth_scale_m, const PinholeCamera& camera,
            const Eigen::Isometry3d& T_W_C);
  /// Waits until every queued frame is in the map. Rethrows what the thread met, if anything
  /// (only a failed allocation can get past push()'s check).
  void finish();

 private:
  struct Job {
    DepthImage depth;
    double depth_scale_m = 0.0;
    PinholeCamera camera;
    Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  };
  void run();

  OccupancyMap* map_;
  std::vector<Job> ring_;  // depth buffers reused frame after frame
  size_t head_ = 0;        // next job to integrate
  size_t queued_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::thread thread_;
};

}  // namespace panmap
