// Mapper::remap(): every frame mapped again at new poses (the repair of a large loop closure).
#include <chrono>
#include <string>
#include <utility>

#include "panmap/core/error.h"
#include "panmap/mapper/map_rebuild.h"
#include "panmap/mapper/mapper.h"

namespace panmap {

void Mapper::checkRepairPoses(const std::vector<StampedPose>& poses, const char* what) const {
  if (poses.size() != trajectory_.size()) {
    throw Error(std::string(what) + ": " + std::to_string(poses.size()) + " poses for " +
                std::to_string(trajectory_.size()) + " integrated frames");
  }
  for (size_t i = 0; i < poses.size(); ++i) {
    if (poses[i].utime != trajectory_[i].utime) {
      throw Error(std::string(what) + ": pose " + std::to_string(i) + " has utime " +
                  std::to_string(poses[i].utime) + ", the frame integrated there " +
                  std::to_string(trajectory_[i].utime));
    }
    std::string why;
    if (!isRigidTransform(poses[i].T_W_C.matrix(), 1e-4, &why)) {
      throw Error(std::string(what) + ": pose of utime " + std::to_string(poses[i].utime) + ": " +
                  why);
    }
  }
}

ReintegrationStats Mapper::remap(const std::vector<StampedPose>& poses,
                                 const PanopticFrameLoader& load,
                                 const ReintegrationProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  if (!load) throw Error("remap: no frame loader");
  checkRepairPoses(poses, "remap");
  ReintegrationStats stats;
  stats.reassociated = true;
  stats.blocks_before = map_->numBlocks();
  const auto seconds = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  // A mapper of its own, with the poses as given: the live one stays whole until the end.
  std::unique_ptr<MapRebuild> rebuild = beginRebuild(nullptr, true);
  RgbdFrame frame;
  PanopticFrame panoptic;
  for (size_t i = 0; i < poses.size(); ++i) {
    const int64_t utime = poses[i].utime;
    const bool has_panoptic = load(utime, &frame, &panoptic);
    if (frame.utime != utime) {
      throw Error("remap: asked for the frame of utime " + std::to_string(utime) + ", got " +
                  std::to_string(frame.utime));
    }
    try {
      rebuild->add(frame, poses[i].T_W_C, nullptr, has_panoptic ? &panoptic : nullptr);
    } catch (const Error& e) {
      throw Error(std::string("remap: ") + e.what());
    }
    ++stats.frames;
    stats.frames_moved += poses[i].T_W_C.matrix() != trajectory_[i].T_W_C.matrix();
    if (progress && !progress(i + 1, poses.size())) {
      stats.frames = 0;
      stats.frames_moved = 0;
      stats.blocks_after = stats.blocks_before;
      stats.seconds = seconds();
      return stats;
    }
  }
  stats.votes_evicted = rebuild->votesEvicted();
  commitRebuild(std::move(rebuild));
  stats.completed = true;
  stats.blocks_after = map_->numBlocks();
  stats.seconds = seconds();
  return stats;
}

void Mapper::adoptRemapped(Mapper* fresh) {
  std::swap(pool_, fresh->pool_);
  std::swap(map_, fresh->map_);
  std::swap(segmenter_, fresh->segmenter_);
  std::swap(tracker_, fresh->tracker_);
  std::swap(integrator_, fresh->integrator_);
  std::swap(graph_, fresh->graph_);
  std::swap(occupancy_, fresh->occupancy_);
  mesher_->setPool(pool_.get());
  vote_evictions_ = fresh->vote_evictions_;
  superpoints_forgotten_ += fresh->superpoints_forgotten_;
  edges_pruned_ += fresh->edges_pruned_;
}

}  // namespace panmap
