#include "panmap/mapper/mapper.h"

#include <chrono>
#include <cmath>
#include <set>
#include <sstream>

#include "panmap/core/error.h"
#include "panmap/core/pose.h"

namespace panmap {

void MapperConfig::check() const {
  map.check();
  integrator.check();
  depth_segmentation.check();
  fusion.check();
  superpoints.check();
  graph.check();
  if (num_threads < 1 || num_threads > 256) throw Error("mapper num_threads must be in [1, 256]");
}

Mapper::Mapper(const MapperConfig& config) : config_(config) {
  config_.check();
  pool_ = std::make_unique<ThreadPool>(config_.num_threads);
  map_ = std::make_unique<TsdfMap>(config_.map);
  // The pipeline's thread count applies to every stage.
  config_.depth_segmentation.num_threads = config_.num_threads;
  segmenter_ =
      std::make_unique<PanopticGeometricSegmenter>(config_.depth_segmentation, config_.fusion);
  tracker_ = std::make_unique<SuperpointTracker>(config_.superpoints);
  integrator_ = std::make_unique<ProjectiveIntegrator>(config_.integrator, pool_.get());
  MarchingCubesConfig mesh_config;
  // A sign change is a surface only between samples closer than the truncation band.
  mesh_config.max_sdf_jump_voxels = config_.integrator.truncation_voxels;
  mesher_ = std::make_unique<IncrementalMesher>(mesh_config, pool_.get());
  graph_ = std::make_unique<GraphAccumulator>(config_.graph);
}

LabelledMesh Mapper::extractMesh(const GraphLabels* labels) {
  mesher_->update(map_.get());
  const SuperpointTracker& tracker = *tracker_;
  MeshLabeller labeller;
  labeller.superpoint = [&tracker](const Voxel& voxel) {
    return argmaxLabel(voxel, [&tracker](int32_t l) { return tracker.labels().resolve(l); });
  };
  labeller.semantic = [&tracker, labels](int32_t label) {
    if (labels) {
      const auto it = labels->semantic.find(label);
      if (it != labels->semantic.end()) return it->second;
    }
    const SuperpointState* s = tracker.state(label);
    return s ? s->semanticClass() : 0;
  };
  labeller.instance = [&tracker, labels](int32_t label) {
    if (labels) {
      const auto it = labels->instance.find(label);
      if (it != labels->instance.end()) return it->second;
    }
    const SuperpointState* s = tracker.state(label);
    return s ? s->instance() : 0;
  };
  return mesher_->assemble(*map_, labeller);
}

void Mapper::validate(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                      const PanopticFrame* panoptic) const {
  std::string why;
  if (!isRigidTransform(T_W_C.matrix(), 1e-4, &why)) throw Error("pose: " + why);
  if (!frame.camera.isValid(&why)) throw Error("intrinsics: " + why);
  if (!(frame.depth_scale_m > 0.0 && std::isfinite(frame.depth_scale_m))) {
    throw Error("depth scale must be > 0");
  }
  const int w = frame.camera.width, h = frame.camera.height;
  if (frame.depth.empty()) throw Error("empty depth image");
  if (frame.depth.width() != w || frame.depth.height() != h) {
    std::ostringstream s;
    s << "depth is " << frame.depth.width() << "x" << frame.depth.height()
      << " but the intrinsics say " << w << "x" << h;
    throw Error(s.str());
  }
  if (!frame.color.empty() && (frame.color.width() != w || frame.color.height() != h)) {
    throw Error("colour image size differs from the depth image's");
  }
  if (panoptic) {
    if (panoptic->segment_ids.width() != w || panoptic->segment_ids.height() != h) {
      std::ostringstream s;
      s << "panoptic mask is " << panoptic->segment_ids.width() << "x"
        << panoptic->segment_ids.height() << " but the depth image is " << w << "x" << h;
      throw Error(s.str());
    }
    std::set<int32_t> ids;
    for (const PanopticSegment& seg : panoptic->segments) {
      if (seg.id <= 0 || !ids.insert(seg.id).second) {
        throw Error("panoptic segment ids must be positive and unique");
      }
      if (!(seg.score >= 0.0f && seg.score <= 1.0f)) throw Error("panoptic score outside [0, 1]");
    }
  }
}

FrameStats Mapper::integrate(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                             const PanopticFrame* panoptic) {
  using Clock = std::chrono::steady_clock;
  auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  validate(frame, T_W_C, panoptic);
  FrameStats stats;
  const auto t0 = Clock::now();
  const FrameSegmentation segmentation =
      segmenter_->segment(frame, config_.fusion.geometry_only ? nullptr : panoptic);
  const auto t1 = Clock::now();
  const FrameAssociation association = tracker_->associate(segmentation, frame, T_W_C, *map_);
  const auto t2 = Clock::now();
  stats.integration = integrator_->integrate(frame, T_W_C, &association.pixel_labels, map_.get());
  const auto t3 = Clock::now();
  if (panoptic && !config_.fusion.geometry_only) {
    graph_->update(frame, T_W_C, *panoptic, *map_, *tracker_, config_.fusion.stuff_confidence);
  }
  const auto t4 = Clock::now();
  stats.graph_ms = ms(t3, t4);
  stats.segmentation_ms = ms(t0, t1);
  stats.superpoints_ms = ms(t1, t2);
  stats.integration_ms = ms(t2, t3);
  stats.total_ms = ms(t0, t4);
  stats.surfaces = static_cast<int>(segmentation.surface_list.size());
  stats.new_superpoints = association.new_labels;
  stats.merges = association.merges;
  vote_evictions_ += stats.integration.votes_evicted;
  ++frames_;
  return stats;
}

}  // namespace panmap
