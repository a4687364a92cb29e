#pragma once

#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/frame.h"
#include "panmap/core/pose.h"
#include "panmap/core/thread_pool.h"
#include "panmap/mapper/mapper.h"
#include "panmap/occupancy/occupancy_map.h"

namespace panmap {

/// The occupancy map of a repair, built ahead of the rest (MapRepairConfig::occupancy_first):
/// every frame the mapper holds, in order, at its new pose, into an occupancy tree of its own,
/// which Mapper::replaceOccupancy() swaps in while the label-TSDF is still being rebuilt. A
/// planner's phantom obstacles go within seconds; the full repair later brings the same tree
/// (the same frames at the same poses, in the same order).
class OccupancyRebuild {
 public:
  /// @param config the mapper's configuration (occupancy and depth calibration are used)
  /// @param pool threads for the depth calibration (not owned; must outlive this)
  OccupancyRebuild(const MapperConfig& config, ThreadPool* pool);

  /// Integrates one frame at T_W_C, its depth corrected as Mapper::integrate() corrects it.
  /// Throws Error naming the frame's utime when the frame or the pose is invalid; nothing is
  /// added then.
  void add(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C);
  /// The frames added so far: utime and pose, in order.
  const std::vector<StampedPose>& poses() const { return poses_; }
  /// Hands the tree over (for Mapper::replaceOccupancy); the rebuild is empty afterwards.
  std::unique_ptr<OccupancyMap> take() { return std::move(occupancy_); }

 private:
  MapperConfig config_;
  ThreadPool* pool_;
  std::unique_ptr<OccupancyMap> occupancy_;
  std::vector<StampedPose> poses_;
  RgbdFrame calibrated_;  // scratch: the frame with the depth calibration applied
};

}  // namespace panmap
