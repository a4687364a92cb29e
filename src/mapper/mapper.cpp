#include "panmap/mapper/mapper.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <iterator>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

#include "panmap/core/error.h"
#include "panmap/core/pose.h"
#include "panmap/mapper/final_labels.h"
#include "panmap/superpoint/vote_split.h"

namespace panmap {

void MapperConfig::check() const {
  map.check();
  integrator.check();
  depth_segmentation.check();
  fusion.check();
  mask_edge_fill.check();
  superpoints.check();
  graph.check();
  occupancy.check();
  tracking.check();
  drift.check();
  depth_check.check();
  if (tracking_warmup_frames < 0) throw Error("mapper tracking_warmup_frames must be >= 0");
  if (num_threads < 1 || num_threads > 256) throw Error("mapper num_threads must be in [1, 256]");
}

Mapper::Mapper(const MapperConfig& config)
    : config_(config),
      drift_(config.drift),
      depth_check_(config.depth_check, kResidualCellsX * kResidualCellsY) {
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
  graph_ = std::make_unique<GraphAccumulator>(config_.graph, pool_.get());
  if (config_.occupancy_enabled) occupancy_ = std::make_unique<OccupancyMap>(config_.occupancy);
  aligner_ = std::make_unique<FrameToModelAligner>(config_.tracking);
}

MeshLabeller Mapper::meshLabeller(const GraphLabels* labels,
                                  absl::flat_hash_map<int32_t, SuperpointLabels>* cache) const {
  // Captured by pointer: the labeller outlives this call.
  const SuperpointTracker* tracker = tracker_.get();
  auto lookup = [tracker, labels, cache](int32_t label) -> const SuperpointLabels& {
    auto [it, inserted] = cache->try_emplace(label);
    if (inserted) it->second = finalLabels(label, *tracker, labels);
    return it->second;
  };
  MeshLabeller labeller;
  labeller.superpoint = [tracker](const VoxelVotes& votes) {
    return argmaxLabel(votes, [tracker](int32_t l) { return tracker->labels().resolve(l); });
  };
  labeller.semantic = [lookup](int32_t label) { return lookup(label).semantic; };
  labeller.instance = [lookup](int32_t label) { return lookup(label).instance; };
  labeller.fill_from_neighbours = true;
  return labeller;
}

LabelledMesh Mapper::extractMesh(const GraphLabels* labels) {
  mesher_->update(map_.get());
  absl::flat_hash_map<int32_t, SuperpointLabels> cache;
  return mesher_->assemble(*map_, meshLabeller(labels, &cache));
}

void Mapper::releaseMeshCache() { mesher_->clear(); }

LabelledMesh Mapper::extractFinalMesh(const GraphLabels* labels) {
  releaseMeshCache();
  absl::flat_hash_map<int32_t, SuperpointLabels> cache;
  return marchingCubes(*map_, mesher_->config(), meshLabeller(labels, &cache), pool_.get());
}

LabelledMesh MeshUpdate::mesh(size_t i) const {
  const BlockMesh& block = *geometry.at(i);
  LabelledMesh out;
  out.vertices = block.vertices;
  out.colors = block.colors;
  out.faces = block.faces;
  out.superpoint = labels.at(i).superpoint;
  out.semantic = labels.at(i).semantic;
  out.instance = labels.at(i).instance;
  return out;
}

MeshUpdate Mapper::updateMesh(const GraphLabels* labels) {
  // Every thread labels the blocks it has just meshed, while their voxels are in cache, with
  // its own cache of super-point labels; resolve() only reads once the registry is flattened.
  tracker_->labels().flatten();
  const int threads = pool_->size();
  std::vector<absl::flat_hash_map<int32_t, SuperpointLabels>> caches(threads);
  std::vector<MeshLabeller> labellers;
  for (auto& cache : caches) labellers.push_back(meshLabeller(labels, &cache));
  std::vector<std::unique_ptr<BlockMeshLabeller>> block_labellers;
  for (const MeshLabeller& labeller : labellers) {
    block_labellers.push_back(std::make_unique<BlockMeshLabeller>(*map_, labeller));
  }
  std::vector<std::vector<std::pair<BlockIndex, BlockLabels>>> labelled(threads);
  mesher_->update(map_.get(), [&](const BlockMesh& mesh, int thread) {
    labelled[thread].emplace_back(mesh.index, block_labellers[thread]->labels(mesh));
  });
  // Sorted as (block, thread, position) triples, not as the labels themselves: each is moved
  // once, into its place.
  std::vector<std::tuple<BlockIndex, int, size_t>> all;
  for (int t = 0; t < threads; ++t) {
    for (size_t k = 0; k < labelled[t].size(); ++k) all.emplace_back(labelled[t][k].first, t, k);
  }
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
    return blockIndexLess(std::get<0>(a), std::get<0>(b));
  });
  MeshUpdate update;
  update.blocks = mesher_->takeChangedBlocks();
  update.geometry.resize(update.blocks.size());
  update.labels.resize(update.blocks.size());
  // Both lists are sorted; blocks re-meshed earlier by extractMesh() are labelled now.
  auto next = all.begin();
  for (size_t i = 0; i < update.blocks.size(); ++i) {
    update.geometry[i] = mesher_->share(update.blocks[i]);
    if (next != all.end() && std::get<0>(*next) == update.blocks[i]) {
      update.labels[i] = std::move(labelled[std::get<1>(*next)][std::get<2>(*next)].second);
      ++next;
    } else if (update.geometry[i]) {
      update.labels[i] = block_labellers[0]->labels(*update.geometry[i]);
    } else {
      // A block dropped by a rebuild and not meshed since has no surface any more.
      auto empty = std::make_shared<BlockMesh>();
      empty->index = update.blocks[i];
      update.geometry[i] = std::move(empty);
    }
  }
  return update;
}

void Mapper::validate(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                      const PanopticFrame* panoptic) const {
  checkFrame(config_, frame, T_W_C, panoptic);
}

void checkFrame(const MapperConfig& config, const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                const PanopticFrame* panoptic) {
  std::string why;
  if (!isRigidTransform(T_W_C.matrix(), 1e-4, &why)) throw Error("pose: " + why);
  if (!frame.camera.isValid(&why)) throw Error("intrinsics: " + why);
  if (!(frame.depth_scale_m > 0.0 && std::isfinite(frame.depth_scale_m))) {
    throw Error("depth scale must be > 0");
  }
  const int w = frame.camera.width, h = frame.camera.height;
  // Every point the frame can produce must lie where the map can address it: block indices
  // wrap at 2^20 blocks from the origin and voxel coordinates are converted to int from
  // float. A depth scale, focal length, principal point or translation far out of range
  // (an LCM frame with depth_scale_m 3.6e52 reached the float-to-int conversion as NaN in
  // fuzz/fuzz_lcm_session) is refused here instead.
  {
    const PinholeCamera& c = frame.camera;
    // The per-pixel geometry runs in float: intrinsics must be far inside its range (an fx of
    // 2e233 overflowed an int conversion in the integrator).
    constexpr double kMaxIntrinsicPx = 1e6;
    for (double v : {c.fx, c.fy, c.cx, c.cy}) {
      if (!(std::abs(v) <= kMaxIntrinsicPx)) {
        throw Error("intrinsics: fx, fy, cx, cy must be within 1e6 pixels");
      }
    }
    const double tan_x = std::max(std::abs(c.cx), std::abs(w - 1 - c.cx)) / c.fx;
    const double tan_y = std::max(std::abs(c.cy), std::abs(h - 1 - c.cy)) / c.fy;
    const double reach =
        T_W_C.translation().norm() +
        65535.0 * frame.depth_scale_m * std::sqrt(1.0 + tan_x * tan_x + tan_y * tan_y);
    const double extent = 0.5 * kBlockSide * config.map.voxel_size_m * static_cast<double>(1 << 20);
    if (!(reach < extent)) {
      std::ostringstream s;
      s << "extent: with its pose, depth scale and intrinsics the frame reaches " << reach
        << " m from the origin, beyond the map's " << extent << " m";
      throw Error(s.str());
    }
  }
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
      if (seg.id <= 0 || seg.id > kMaxPanopticSegmentId || !ids.insert(seg.id).second) {
        throw Error("panoptic segment ids must be unique and in 1.." +
                    std::to_string(kMaxPanopticSegmentId) + " (got " + std::to_string(seg.id) +
                    ")");
      }
      if (!(seg.score >= 0.0f && seg.score <= 1.0f)) throw Error("panoptic score outside [0, 1]");
    }
  }
}

size_t Mapper::refreshSurfaceScan() const {
  return graph_->surfaceScan(*map_, tracker_->labels()).blocksRead();
}

void Mapper::forgetUnvotedSuperpoints() {
  const LabelRegistry& registry = tracker_->labels();
  // Reads only the blocks changed since the last look: a whole-map read every
  // kForgetEveryFrames frames took 0.4 s on 84k blocks of the 2 cm building (213k in all).
  const SurfaceScan& scan = graph_->surfaceScan(*map_, registry);
  const std::vector<uint8_t> has_votes = scan.hasVotes();
  superpoints_forgotten_ += tracker_->forgetUnvoted(has_votes);
  graph_->forgetUnvoted(has_votes, registry);
  if (config_.graph.prune_edges) edges_pruned_ += graph_->pruneEdges(scan.adjacency(), registry);
}

FrameStats Mapper::integrate(const RgbdFrame& raw_frame, const Eigen::Isometry3d& T_W_C_given,
                             const PanopticFrame* panoptic, PoseSource source,
                             const GeometricSegments* kept) {
  using Clock = std::chrono::steady_clock;
  auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  validate(raw_frame, T_W_C_given, panoptic);
  // Every stage sees the calibrated depth: tracking and the map must agree on the geometry
  // (correcting only the frames aligned to an uncorrected map was measured to make pose
  // refinement worse, docs/MAPPING.md).
  const bool calibrated = config_.hasDepthCalibration();
  if (calibrated) config_.depth_calibration->apply(raw_frame, &calibrated_frame_, pool_.get());
  const RgbdFrame& frame = calibrated ? calibrated_frame_ : raw_frame;
  pose_convention_watch_.add(frame, T_W_C_given);
  FrameStats stats;
  const auto t_start = Clock::now();
  // Refine the pose against the map first: every later stage then sees the refined pose.
  Eigen::Isometry3d T_W_C = T_W_C_given;
  const bool forced = config_.tracking_mode == MapperConfig::TrackingMode::kOn;
  const bool track = forced || (config_.tracking_mode == MapperConfig::TrackingMode::kAuto &&
                                (source == PoseSource::kSlam || source == PoseSource::kOdometry));
  // Auto mode corrects poses only with depth it can trust (MapperConfig::depth_check): the
  // first frames are refined and kept while their alignments judge the depth.
  DepthPatternMonitor::Verdict verdict =
      forced || calibrated ? DepthPatternMonitor::Verdict::kTrusted : depth_check_.verdict();
  const bool judging = track && verdict == DepthPatternMonitor::Verdict::kPending;
  if (frames_ == 0) probation_complete_ = judging;
  if (track && verdict == DepthPatternMonitor::Verdict::kUncalibrated) {
    // No alignment any more. The correction held when the check decided without the frames
    // to revert (an overflowed probation) keeps the map from tearing; after a revert it is none.
    T_W_C = drift_.predict(T_W_C_given);
    stats.pose_kept = true;
    ++poses_kept_;
  } else if (track) {
    // The drift estimate follows every tracked frame (its uncertainty grows with the motion),
    // the map corrects it once it has a model to align against.
    const Eigen::Isometry3d prior = drift_.predict(T_W_C_given);
    T_W_C = prior;
    if (frames_ >= config_.tracking_warmup_frames) {
      const AlignmentResult result = aligner_->align(*map_, frame, prior);
      stats.tracked = true;
      stats.tracking_status = result.status;
      ++tracking_counts_[static_cast<size_t>(result.status)];
      if (judging && result.accepted) {
        verdict = depth_check_.add(result.cell_sum_m, result.cell_count);
      }
      if (verdict == DepthPatternMonitor::Verdict::kUncalibrated) {
        // This alignment decided: the frame goes in as given, and the refined ones before it
        // are integrated again as given once it is in (revertProbation).
        if (probation_complete_ && probation_.size() < kMaxProbationFrames) T_W_C = T_W_C_given;
        stats.pose_kept = true;
        ++poses_kept_;
      } else if (result.accepted) {
        // A refused frame keeps the predicted correction rather than jumping back to the raw
        // pose, which would tear the map where it joins the corrected part.
        ++poses_corrected_;
        T_W_C = config_.tracking_correction == MapperConfig::PoseCorrection::kFilter
                    ? drift_.update(result.delta, result.information)
                    : drift_.adopt(result.T_W_C);
      }
    }
  }
  stats.T_W_C = T_W_C;
  const auto t0 = Clock::now();
  stats.tracking_ms = stats.tracked ? ms(t_start, t0) : 0.0;
  FrameSegmentation& segmentation = segmentation_;
  segmenter_->segment(frame, config_.fusion.geometry_only ? nullptr : panoptic, &segmentation,
                      kept);
  frames_with_kept_segments_ += segmenter_->keptLast();
  const auto t1 = Clock::now();
  // Association runs on one thread, so the occupancy update (which needs only the frame and
  // its pose) takes the other one meanwhile.
  FrameAssociation& association = association_;
  std::exception_ptr failures[2];
  pool_->parallelFor(2, [&](size_t begin, size_t end, int) {
    for (size_t task = begin; task < end; ++task) {
      try {
        const auto start = Clock::now();
        if (task == 0) {
          tracker_->associate(segmentation, frame, T_W_C, *map_, &association);
          stats.superpoints_ms = ms(start, Clock::now());
        } else if (occupancy_) {
          occupancy_->integrate(frame, T_W_C);
          stats.occupancy_ms = ms(start, Clock::now());
        }
      } catch (...) {
        failures[task] = std::current_exception();
      }
    }
  });
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
  applySplits(&association, segmentation, frame, T_W_C, tracker_->labels(), map_.get());
  if (panoptic && !config_.fusion.geometry_only) {
    fillMaskEdges(frame.depth, *panoptic, config_.mask_edge_fill, &association.pixel_labels,
                  &fill_scratch_, pool_.get());
  }
  const auto t2 = Clock::now();
  stats.integration = integrator_->integrate(frame, T_W_C, &association.pixel_labels, map_.get());
  const auto t3 = Clock::now();
  if (panoptic && !config_.fusion.geometry_only) {
    graph_->applySplits(association.splits, *tracker_);
    graph_->update(frame, T_W_C, *panoptic, *map_, *tracker_, config_.fusion.stuff_confidence);
  }
  if ((frames_ + 1) % kForgetEveryFrames == 0) forgetUnvotedSuperpoints();
  const auto t4 = Clock::now();
  stats.graph_ms = ms(t3, t4);
  stats.segmentation_ms = ms(t0, t1);
  stats.integration_ms = ms(t2, t3);
  stats.total_ms = ms(t_start, t4);
  stats.surfaces = static_cast<int>(segmentation.surface_list.size());
  stats.new_superpoints = association.new_labels;
  stats.merges = association.merges;
  vote_evictions_ += stats.integration.votes_evicted;
  StampedPose used;
  used.utime = frame.utime;
  used.frame_id = frame.frame_id;
  used.T_W_C = T_W_C;
  used.source = source;
  trajectory_.push_back(used);
  ++frames_;
  if (judging && probation_complete_ && probation_.size() < kMaxProbationFrames) {
    probation_.push_back({frame, T_W_C_given, association.pixel_labels});
  } else if (probation_complete_) {
    // Overflowed, tracking no longer applies (a pose not flagged SLAM or odometry), or the
    // check trusted the depth: nothing will be reverted.
    probation_complete_ = false;
    probation_ = std::vector<ProbationFrame>();
  }
  if (judging && verdict == DepthPatternMonitor::Verdict::kUncalibrated) {
    stats.reverted_frames = revertProbation();
  }
  return stats;
}

int Mapper::revertProbation() {
  const bool complete = probation_complete_ && probation_.size() == trajectory_.size();
  probation_complete_ = false;
  std::vector<ProbationFrame> frames = std::move(probation_);
  probation_ = std::vector<ProbationFrame>();
  if (!complete) return 0;
  std::unique_ptr<MapRebuild> rebuild = beginRebuild(nullptr, false);
  int64_t refined = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    refined += !trajectory_[i].T_W_C.isApprox(frames[i].T_W_C_given, 0.0);
    rebuild->add(frames[i].frame, frames[i].T_W_C_given, &frames[i].pixel_labels);
  }
  // Sets the trajectory to the given poses and the drift estimate back to none.
  commitRebuild(std::move(rebuild));
  poses_kept_ += refined;
  poses_corrected_ = 0;
  return static_cast<int>(frames.size());
}

}  // namespace panmap
