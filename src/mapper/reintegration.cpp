// Mapper::reintegrate(): the map rebuilt from its frames at new poses (a loop closure's repair).
#include <chrono>
#include <map>
#include <string>
#include <utility>

#include "panmap/core/error.h"
#include "panmap/mapper/frame_prefetcher.h"
#include "panmap/mapper/instance_carry_over.h"
#include "panmap/mapper/mapper.h"
#include "panmap/mapper/superpoint_rejoin.h"

namespace panmap {

std::unique_ptr<MapRebuild> Mapper::beginRebuild(ThreadPool* pool, bool remap) const {
  return std::make_unique<MapRebuild>(config_, pool ? pool : pool_.get(), remap);
}

void Mapper::commitRebuild(std::unique_ptr<MapRebuild> rebuild, ReintegrationStats* stats) {
  if (!rebuild) throw Error("commitRebuild: no rebuild");
  const std::vector<StampedPose>& poses = rebuild->poses();
  if (poses.size() != trajectory_.size()) {
    throw Error("commitRebuild: the rebuild holds " + std::to_string(poses.size()) +
                " frames, the map " + std::to_string(trajectory_.size()));
  }
  for (size_t i = 0; i < poses.size(); ++i) {
    if (poses[i].utime != trajectory_[i].utime) {
      throw Error("commitRebuild: frame " + std::to_string(i) + " of the rebuild has utime " +
                  std::to_string(poses[i].utime) + ", the map's " +
                  std::to_string(trajectory_[i].utime));
    }
  }
  if (rebuild->remaps()) {
    if (rebuild->mapper_->config_.occupancy_enabled != config_.occupancy_enabled) {
      throw Error("commitRebuild: the rebuild was made with another occupancy setting");
    }
    // The remap numbered its instances and super-points anew: those that hold an old one's
    // surface take its id, so objects keep the ids a planner knows them by and super-points the
    // ids the graph and the optimiser's labels know them by (docs/LOOP_CLOSURE.md).
    Mapper& fresh = *rebuild->mapper_;
    const auto carry_start = std::chrono::steady_clock::now();
    const CarryOverlap overlap =
        countCarryOverlap(rebuild->instance_samples_, trajectory_, *map_, *tracker_, *fresh.map_,
                          *fresh.tracker_, pool_.get());
    int32_t next_instance = 1;
    const std::map<int32_t, int32_t> instance_ids =
        carriedInstanceIds(overlap.instances, fresh.tracker_->numInstances() + 1,
                           tracker_->numInstances() + 1, &next_instance);
    const std::vector<int32_t> superpoints = fresh.liveSuperpoints();
    int32_t next_label = 1;
    const std::map<int32_t, int32_t> superpoint_ids =
        carriedIds(overlap.superpoints, superpoints, tracker_->labels().size() + 1, &next_label);
    fresh.tracker_->renumberInstances(instance_ids, next_instance);
    fresh.renumberSuperpoints(superpoint_ids, next_label - 1);
    if (stats) {
      const auto kept = [](const std::map<int32_t, int32_t>& ids, int32_t old_next) {
        size_t n = 0;
        for (const auto& entry : ids) n += entry.second < old_next ? 1 : 0;
        return n;
      };
      stats->instances = instance_ids.size();
      stats->instances_kept = kept(instance_ids, tracker_->numInstances() + 1);
      stats->superpoints = superpoint_ids.size();
      stats->superpoints_kept = kept(superpoint_ids, tracker_->labels().size() + 1);
      const auto sameId = [](const IdOverlap& overlap, const std::map<int32_t, int32_t>& ids) {
        size_t same = 0, all = 0;
        for (const auto& [pair, samples] : overlap) {
          const auto it = ids.find(pair.first);
          same += it != ids.end() && it->second == pair.second ? samples : 0;
          all += samples;
        }
        return all > 0 ? static_cast<double>(same) / static_cast<double>(all) : 0.0;
      };
      stats->instance_surface_kept = sameId(overlap.instances, instance_ids);
      stats->superpoint_surface_kept = sameId(overlap.superpoints, superpoint_ids);
      stats->stage_median_ms = rebuild->stageMedians();
      stats->carry_over_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - carry_start).count();
    }
    adoptRemapped(rebuild->mapper_.get());
  } else {
    if (static_cast<bool>(rebuild->occupancy_) != static_cast<bool>(occupancy_)) {
      throw Error("commitRebuild: the rebuild was made with another occupancy setting");
    }
    // First, as it may throw (its thread's error): nothing is swapped in before it.
    std::unique_ptr<OccupancyMap> occupancy = rebuild->takeOccupancy();
    // A surface that association missed under drift has two super-points; voting again at
    // the corrected poses lays them over one another.
    const auto rejoin_start = std::chrono::steady_clock::now();
    const size_t rejoined = rejoinCoincidingSuperpoints(*rebuild->map_, map_.get(), tracker_.get());
    graph_->applyMerges(*tracker_);
    tracker_->labels().flatten();  // threads that label voxels only read the registry
    map_ = std::move(rebuild->map_);
    if (occupancy_) occupancy_ = std::move(occupancy);
    // The evictions of building this map, which replaces the old one and its history.
    vote_evictions_ = rebuild->votesEvicted();
    if (stats) {
      stats->superpoints_rejoined = rejoined;
      stats->rejoin_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - rejoin_start).count();
    }
  }
  mesher_->invalidateAll();
  for (size_t i = 0; i < poses.size(); ++i) trajectory_[i].T_W_C = poses[i].T_W_C;
  // The correction's keyframes now sit at the back-end's poses, and the newest frames at what
  // its corrected odometry gives them: what the tracker had learnt of the old drift is void.
  drift_ = DriftFilter(config_.drift);
}

void Mapper::replaceOccupancy(std::unique_ptr<OccupancyMap> occupancy,
                              const std::vector<StampedPose>& poses) {
  if (!occupancy) throw Error("replaceOccupancy: no occupancy map");
  if (!occupancy_) throw Error("replaceOccupancy: this mapper keeps no occupancy map");
  checkRepairPoses(poses, "replaceOccupancy");
  occupancy_ = std::move(occupancy);
}

ReintegrationStats Mapper::reintegrate(const std::vector<StampedPose>& poses,
                                       const FrameLoader& load,
                                       const ReintegrationProgress& progress) {
  if (!load) throw Error("reintegrate: no frame loader");
  checkRepairPoses(poses, "reintegrate");
  std::vector<int64_t> utimes;
  for (const StampedPose& p : poses) utimes.push_back(p.utime);
  FramePrefetcher frames(load, std::move(utimes));
  return rebuildFrom(poses, &frames, false, "reintegrate", progress);
}

ReintegrationStats Mapper::remap(const std::vector<StampedPose>& poses,
                                 const PanopticFrameLoader& load,
                                 const ReintegrationProgress& progress) {
  if (!load) throw Error("remap: no frame loader");
  checkRepairPoses(poses, "remap");
  std::vector<int64_t> utimes;
  for (const StampedPose& p : poses) utimes.push_back(p.utime);
  FramePrefetcher frames(load, std::move(utimes));
  return rebuildFrom(poses, &frames, true, "remap", progress);
}

ReintegrationStats Mapper::rebuildFrom(const std::vector<StampedPose>& poses,
                                       FramePrefetcher* frames, bool remap, const char* what,
                                       const ReintegrationProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  ReintegrationStats stats;
  stats.reassociated = remap;
  stats.blocks_before = map_->numBlocks();
  const auto seconds = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  // Built aside: the live maps stay whole until the last frame is in. The prefetcher decodes
  // the next frame while this one is integrated, which keeps the second core busy.
  std::unique_ptr<MapRebuild> rebuild = beginRebuild(nullptr, remap);
  RgbdFrame frame;
  LabelImage labels;
  PanopticFrame panoptic;
  GeometricSegments kept;
  for (size_t i = 0; i < poses.size(); ++i) {
    const int64_t utime = poses[i].utime;
    const bool has_panoptic = frames->next(&frame, &labels, &panoptic, &kept);
    if (frame.utime != utime) {
      throw Error(std::string(what) + ": asked for the frame of utime " + std::to_string(utime) +
                  ", got " + std::to_string(frame.utime));
    }
    try {
      rebuild->add(frame, poses[i].T_W_C, &labels, has_panoptic ? &panoptic : nullptr,
                   kept.ids.empty() ? nullptr : &kept);
    } catch (const Error& e) {
      throw Error(std::string(what) + ": " + e.what());
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
  stats.frames_with_kept_segments = rebuild->framesWithKeptSegments();
  commitRebuild(std::move(rebuild), &stats);
  stats.completed = true;
  stats.blocks_after = map_->numBlocks();
  stats.seconds = seconds();
  return stats;
}

}  // namespace panmap
