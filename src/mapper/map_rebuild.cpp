// MapRebuild: the maps of a repair, built aside from the live ones.
#include "panmap/mapper/map_rebuild.h"

#include <algorithm>
#include <chrono>
#include <string>

#include "panmap/core/error.h"
#include "panmap/core/value_spread.h"
#include "panmap/mapper/mapper.h"

namespace panmap {

MapRebuild::MapRebuild(const MapperConfig& config, ThreadPool* pool, bool remap)
    : config_(std::make_unique<MapperConfig>(config)), pool_(pool) {
  if (!pool) throw Error("MapRebuild: no thread pool");
  if (remap) {
    // The poses are the back-end's corrected ones: nothing to refine them against. The
    // mapper keeps the configured thread count: its pool becomes the live mapper's.
    config_->tracking_mode = MapperConfig::TrackingMode::kOff;
    mapper_ = std::make_unique<Mapper>(*config_);
    return;
  }
  integrator_ = std::make_unique<ProjectiveIntegrator>(config_->integrator, pool);
  map_ = std::make_unique<TsdfMap>(config_->map);
  if (config_->occupancy_enabled) {
    occupancy_ = std::make_unique<OccupancyMap>(config_->occupancy);
    occupancy_lane_ = std::make_unique<OccupancyLane>(occupancy_.get());
  }
}

MapRebuild::~MapRebuild() = default;

std::vector<std::pair<std::string, double>> MapRebuild::stageMedians() const {
  std::vector<std::pair<std::string, double>> out;
  for (const auto& [stage, ms] : stage_ms_) out.emplace_back(stage, spreadOf(ms).median);
  return out;
}

const TsdfMap& MapRebuild::map() const { return mapper_ ? mapper_->map() : *map_; }

size_t MapRebuild::framesWithKeptSegments() const {
  return mapper_ ? static_cast<size_t>(mapper_->framesWithKeptSegments()) : 0;
}

void MapRebuild::add(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                     const LabelImage* labels, const PanopticFrame* panoptic,
                     const GeometricSegments* kept) {
  const std::string name = "frame of utime " + std::to_string(frame.utime);
  StampedPose pose;
  pose.utime = frame.utime;
  pose.T_W_C = T_W_C;
  if (mapper_) {
    FrameStats stats;
    try {
      stats = mapper_->integrate(frame, T_W_C, panoptic, PoseSource::kUnknown, kept);
    } catch (const Error& e) {
      throw Error(name + ": " + e.what());
    }
    votes_evicted_ = mapper_->voteEvictions();
    const auto start = std::chrono::steady_clock::now();
    instance_samples_.push_back(sampleFrame(frame, poses_.size(), T_W_C, kInstanceSampleStepPx,
                                            config_->depth_calibration.get()));
    const double sample_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::vector<std::pair<const char*, double>> times = stats.stageTimes();
    times.emplace_back("instance samples", sample_ms);
    for (const auto& time : times) {
      // By name, as a stage may be missing from a frame ("tracking" when refinement is off).
      // Not a structured binding: C++17 lambdas (clang) cannot capture one.
      const char* stage = time.first;
      auto it = std::find_if(stage_ms_.begin(), stage_ms_.end(),
                             [&](const auto& entry) { return entry.first == stage; });
      if (it == stage_ms_.end())
        it = stage_ms_.emplace(stage_ms_.end(), stage, std::vector<double>{});
      it->second.push_back(time.second);
    }
    poses_.push_back(pose);
    return;
  }
  try {
    checkFrame(*config_, frame, T_W_C, nullptr);
  } catch (const Error& e) {
    throw Error(name + ": " + e.what());
  }
  // Stored frames hold the depth as read: corrected here as Mapper::integrate() corrects it.
  const bool calibrated = config_->hasDepthCalibration();
  if (calibrated) {
    try {
      config_->depth_calibration->apply(frame, &calibrated_, pool_);
    } catch (const Error& e) {
      throw Error(name + ": " + e.what());
    }
  }
  const RgbdFrame& f = calibrated ? calibrated_ : frame;
  const bool labelled = labels && !labels->empty();
  if (labelled &&
      (labels->width() != frame.camera.width || labels->height() != frame.camera.height)) {
    throw Error(name + ": label image " + std::to_string(labels->width()) + "x" +
                std::to_string(labels->height()) + ", depth " + std::to_string(frame.camera.width) +
                "x" + std::to_string(frame.camera.height));
  }
  if (occupancy_) {
    try {
      occupancy_->validate(f.depth, f.depth_scale_m, f.camera, T_W_C);
    } catch (const Error& e) {
      throw Error(name + ": " + e.what());
    }
  }
  const IntegrationStats integration =
      integrator_->integrate(f, T_W_C, labelled ? labels : nullptr, map_.get());
  votes_evicted_ += integration.votes_evicted;
  // The tree follows a few frames behind on a thread of its own: its ray casting fills the
  // gaps the integrator's parallel loops leave on the two cores. Waiting for it frame by frame
  // (as until 2026-12-04) left them idle (docs/LOOP_CLOSURE.md).
  if (occupancy_lane_) occupancy_lane_->push(f.depth, f.depth_scale_m, f.camera, T_W_C);
  poses_.push_back(pose);
}

std::unique_ptr<OccupancyMap> MapRebuild::takeOccupancy() {
  if (occupancy_lane_) {
    occupancy_lane_->finish();
    occupancy_lane_.reset();
  }
  return std::move(occupancy_);
}

}  // namespace panmap
