// Mapper::reintegrate(): the map rebuilt from its frames at new poses (a loop closure's repair).
#include <chrono>
#include <string>
#include <utility>

#include "panmap/core/error.h"
#include "panmap/mapper/mapper.h"

namespace panmap {

ReintegrationStats Mapper::reintegrate(const std::vector<StampedPose>& poses,
                                       const FrameLoader& load,
                                       const ReintegrationProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  if (!load) throw Error("reintegrate: no frame loader");
  if (poses.size() != trajectory_.size()) {
    throw Error("reintegrate: " + std::to_string(poses.size()) + " poses for " +
                std::to_string(trajectory_.size()) + " integrated frames");
  }
  for (size_t i = 0; i < poses.size(); ++i) {
    if (poses[i].utime != trajectory_[i].utime) {
      throw Error("reintegrate: pose " + std::to_string(i) + " has utime " +
                  std::to_string(poses[i].utime) + ", the frame integrated there " +
                  std::to_string(trajectory_[i].utime));
    }
    std::string why;
    if (!isRigidTransform(poses[i].T_W_C.matrix(), 1e-4, &why)) {
      throw Error("reintegrate: pose of utime " + std::to_string(poses[i].utime) + ": " + why);
    }
  }
  ReintegrationStats stats;
  stats.blocks_before = map_->numBlocks();
  // Built aside: the live maps stay whole until the last frame is in.
  auto map = std::make_unique<TsdfMap>(config_.map);
  std::unique_ptr<OccupancyMap> occupancy;
  if (occupancy_) occupancy = std::make_unique<OccupancyMap>(config_.occupancy);
  RgbdFrame frame;
  LabelImage labels;
  for (size_t i = 0; i < poses.size(); ++i) {
    const int64_t utime = poses[i].utime;
    frame = RgbdFrame();
    labels = LabelImage();
    load(utime, &frame, &labels);
    if (frame.utime != utime) {
      throw Error("reintegrate: asked for the frame of utime " + std::to_string(utime) + ", got " +
                  std::to_string(frame.utime));
    }
    try {
      validate(frame, poses[i].T_W_C, nullptr);
    } catch (const Error& e) {
      throw Error("reintegrate: frame of utime " + std::to_string(utime) + ": " + e.what());
    }
    const bool labelled = !labels.empty();
    if (labelled &&
        (labels.width() != frame.camera.width || labels.height() != frame.camera.height)) {
      throw Error("reintegrate: frame of utime " + std::to_string(utime) + ": label image " +
                  std::to_string(labels.width()) + "x" + std::to_string(labels.height()) +
                  ", depth " + std::to_string(frame.camera.width) + "x" +
                  std::to_string(frame.camera.height));
    }
    const IntegrationStats integration =
        integrator_->integrate(frame, poses[i].T_W_C, labelled ? &labels : nullptr, map.get());
    stats.votes_evicted += integration.votes_evicted;
    if (occupancy) occupancy->integrate(frame, poses[i].T_W_C);
    ++stats.frames;
    stats.frames_moved += poses[i].T_W_C.matrix() != trajectory_[i].T_W_C.matrix();
    if (progress && !progress(i + 1, poses.size())) {
      stats.frames = 0;
      stats.frames_moved = 0;
      stats.votes_evicted = 0;
      stats.blocks_after = stats.blocks_before;
      stats.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return stats;
    }
  }
  map_ = std::move(map);
  if (occupancy) occupancy_ = std::move(occupancy);
  mesher_->invalidateAll();
  for (size_t i = 0; i < poses.size(); ++i) trajectory_[i].T_W_C = poses[i].T_W_C;
  // The evictions of building this map, which replaces the old one and its history.
  vote_evictions_ = stats.votes_evicted;
  stats.completed = true;
  stats.blocks_after = map_->numBlocks();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace panmap
