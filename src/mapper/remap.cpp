// The checks and the state transfer shared by Mapper::reintegrate() and Mapper::remap().
#include <string>
#include <utility>

#include "panmap/core/error.h"
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
