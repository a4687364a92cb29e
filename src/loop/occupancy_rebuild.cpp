// OccupancyRebuild: a repair's occupancy tree, built ahead of its label-TSDF.
#include "panmap/loop/occupancy_rebuild.h"

#include <string>

#include "panmap/core/error.h"

namespace panmap {

OccupancyRebuild::OccupancyRebuild(const MapperConfig& config, ThreadPool* pool)
    : config_(config), pool_(pool) {
  if (!pool_) throw Error("OccupancyRebuild: no thread pool");
  if (!config_.occupancy_enabled) throw Error("OccupancyRebuild: the mapper keeps no occupancy");
  occupancy_ = std::make_unique<OccupancyMap>(config_.occupancy);
}

void OccupancyRebuild::add(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C) {
  if (!occupancy_) throw Error("OccupancyRebuild: the tree was handed over");
  const std::string name = "frame of utime " + std::to_string(frame.utime);
  try {
    checkFrame(config_, frame, T_W_C, nullptr);
    const bool calibrated = config_.hasDepthCalibration();
    if (calibrated) config_.depth_calibration->apply(frame, &calibrated_, pool_);
    occupancy_->integrate(calibrated ? calibrated_ : frame, T_W_C);
  } catch (const Error& e) {
    throw Error(name + ": " + e.what());
  }
  StampedPose pose;
  pose.utime = frame.utime;
  pose.T_W_C = T_W_C;
  poses_.push_back(pose);
}

}  // namespace panmap
