#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <absl/container/flat_hash_map.h>
#include <Eigen/Geometry>

#include "panmap/calibration/depth_calibration.h"
#include "panmap/convention/pose_convention_watch.h"
#include "panmap/core/byte_sink.h"
#include "panmap/core/frame.h"
#include "panmap/core/pose.h"
#include "panmap/core/thread_pool.h"
#include "panmap/graph/graph_accumulator.h"
#include "panmap/map/projective_integrator.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/mapper/final_labels.h"
#include "panmap/mapper/map_rebuild.h"
#include "panmap/mesh/incremental_mesher.h"
#include "panmap/occupancy/occupancy_map.h"
#include "panmap/segmentation/mask_edge_fill.h"
#include "panmap/segmentation/panoptic_geometric.h"
#include "panmap/superpoint/superpoint_tracker.h"
#include "panmap/tracking/depth_pattern_monitor.h"
#include "panmap/tracking/drift_filter.h"
#include "panmap/tracking/frame_to_model_aligner.h"

namespace panmap {

/// The blocks whose surface changed since the previous Mapper::updateMesh(), each with its own
/// mesh and labels (as of this call). A viewer keeps one mesh per block and replaces these; an
/// empty mesh means the block has no surface any more. The geometry is the mapper's own block
/// mesh, shared rather than copied (copying it was about a tenth of the update at 1 cm): the
/// mapper never changes a mesh it has handed out, so an update stays valid for as long as it
/// is kept, and re-meshing a block whose mesh is still held costs a new one.
struct MeshUpdate {
  std::vector<BlockIndex> blocks;  ///< in blockIndexLess order
  /// geometry[i]: the mesh of blocks[i] (vertices on its upper borders not welded with the
  /// neighbours'); never null.
  std::vector<std::shared_ptr<const BlockMesh>> geometry;
  std::vector<BlockLabels> labels;  ///< labels[i]: per vertex of geometry[i]

  /// The labelled mesh of blocks[i], geometry and labels together (a copy).
  LabelledMesh mesh(size_t i) const;
};

/// Every parameter of the per-frame pipeline, grouped by component.
struct MapperConfig {
  TsdfMap::Config map;
  IntegratorConfig integrator;
  DepthSegmentationConfig depth_segmentation;
  SurfaceFusionConfig fusion;
  /// Pixels of a mask that no surface holds vote with the mask's surfaces (fillMaskEdges).
  MaskEdgeFillConfig mask_edge_fill;
  SuperpointConfig superpoints;
  GraphConfig graph;
  /// The occupancy tree for planners (OctoMap cells, 5 cm by default).
  bool occupancy_enabled = true;
  OccupancyMap::Config occupancy;
  /// When to refine incoming poses against the map before integrating them.
  enum class TrackingMode : int8_t {
    kOff = 0,   ///< never
    kAuto = 1,  ///< poses flagged as SLAM or odometry (not ground truth, not unknown)
    kOn = 2,    ///< every pose
  };
  TrackingMode tracking_mode = TrackingMode::kAuto;
  /// Frames mapped with their given pose before refinement starts (the map needs a model).
  int tracking_warmup_frames = 5;
  /// How an accepted alignment corrects the poses.
  enum class PoseCorrection : int8_t {
    /// The aligned pose is used as it is and its correction carries over to the next frame
    /// (best on rendered sequences: it also removes per-frame jitter).
    kPerFrame = 0,
    /// Alignments are measurements of a smooth drift correction (DriftFilter): the SLAM
    /// motion is kept (better on real depth, whose per-frame alignments are biased).
    kFilter = 1,
  };
  PoseCorrection tracking_correction = PoseCorrection::kPerFrame;
  /// The aligner; use FrameToModelAligner::Config::forDriftFilter() with kFilter.
  FrameToModelAligner::Config tracking = FrameToModelAligner::Config::forSequences();
  /// The smooth drift estimate (kFilter).
  DriftFilter::Config drift;
  /// kAuto without a depth calibration: the first frames' alignments decide whether the depth
  /// can be trusted to correct poses (DepthPatternMonitor). Meanwhile poses are refined as
  /// usual and the frames are kept; when a fixed error pattern is found, those frames are
  /// integrated again at their given poses and every later pose stays as given. kOn skips the
  /// check; a depth calibration is trusted.
  DepthPatternMonitor::Config depth_check;
  int num_threads = 2;  ///< threads for segmentation and integration (association uses one)
  /// The depth sensor's calibration (panmap-calibrate-depth, docs/MAPPING.md), added to every
  /// frame's depth before anything else reads it; null: the depth as the sensor read it. Kept in
  /// map files, so a loaded map and a loop-closure repair correct frames the same way.
  std::shared_ptr<const DepthCalibration> depth_calibration;
  /// Where depth_calibration was read from (reports only).
  std::string depth_calibration_file;
  /// True when frames are corrected: a calibration is set and not the identity.
  bool hasDepthCalibration() const { return depth_calibration && !depth_calibration->empty(); }
  /// Throws Error naming the bad field.
  void check() const;
};

/// Checks a frame before it touches a map: finite rigid pose, valid intrinsics matching the
/// depth size, colour and mask sizes, positive unique segment ids, scores in [0, 1], every
/// point within the map's extent. Throws Error with a one-line reason.
void checkFrame(const MapperConfig& config, const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                const PanopticFrame* panoptic);

/// Timings and counts of one integrated frame.
struct FrameStats {
  double segmentation_ms = 0.0;  ///< III-A
  double superpoints_ms = 0.0;   ///< III-B association, merging, frame counting
  double integration_ms = 0.0;   ///< label-TSDF update
  double graph_ms = 0.0;         ///< III-C graph update (and every 100th frame, forgetting unvoted)
  double tracking_ms = 0.0;      ///< pose refinement against the map (0 when not run)
  double occupancy_ms = 0.0;     ///< occupancy update (runs alongside the super-point stage)
  double total_ms = 0.0;
  /// The pose the frame was integrated with (the given one, or refined against the map).
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  bool tracked = false;  ///< pose refinement ran
  /// Tracking would have refined the pose, but the depth check found the depth uncalibrated
  /// (MapperConfig::depth_check): the frame was integrated at its given pose.
  bool pose_kept = false;
  /// Frames integrated again at their given poses because this frame's alignment completed a
  /// depth check that found the depth uncalibrated (0 otherwise): the map and trajectory() of
  /// those frames changed.
  int reverted_frames = 0;
  AlignmentStatus tracking_status = AlignmentStatus::kAccepted;  ///< when tracked
  int surfaces = 0;
  int new_superpoints = 0;
  int merges = 0;
  IntegrationStats integration;

  /// The stage times by name, as reports and benchmarks list them ("tracking" only when the
  /// pose was refined), "total" last.
  std::vector<std::pair<const char*, double>> stageTimes() const {
    std::vector<std::pair<const char*, double>> out = {{"segmentation", segmentation_ms},
                                                       {"superpoints", superpoints_ms},
                                                       {"integration", integration_ms},
                                                       {"graph", graph_ms},
                                                       {"occupancy", occupancy_ms}};
    if (tracked) out.emplace_back("tracking", tracking_ms);
    out.emplace_back("total", total_ms);
    return out;
  }
};

/// Loads an integrated frame again for re-integration: its RGB-D data (with the utime asked
/// for) and the super-point label each pixel voted for (empty: geometry only). Throws Error
/// naming the frame when it cannot. Re-integration calls it on a thread of its own (one call
/// at a time, in order), so that decoding overlaps integrating.
using FrameLoader = std::function<void(int64_t utime, RgbdFrame* frame, LabelImage* labels)>;

/// Gives a stored frame back for Mapper::remap(): the frame and, when it was mapped with one,
/// its panoptic segmentation (returns whether it has one), and the geometric segments it was
/// mapped with when they were kept (`kept` left empty otherwise). Throws Error when it cannot.
using PanopticFrameLoader = std::function<bool(int64_t utime, RgbdFrame* frame,
                                               PanopticFrame* panoptic, GeometricSegments* kept)>;

/// Called after each re-integrated frame with (frames done, frames in all); returning false
/// abandons the re-integration (a newer correction supersedes it), leaving the map as it was.
using ReintegrationProgress = std::function<bool(size_t done, size_t total)>;

/// What Mapper::reintegrate() did.
struct ReintegrationStats {
  bool completed = false;      ///< false: abandoned through the progress callback, map unchanged
  size_t frames = 0;           ///< frames re-integrated
  size_t frames_moved = 0;     ///< of those, frames whose pose changed
  size_t blocks_before = 0;    ///< TSDF blocks before
  size_t blocks_after = 0;     ///< and after
  uint64_t votes_evicted = 0;  ///< label votes that pushed out a weaker one while rebuilding
  double seconds = 0.0;        ///< wall time
  /// The frames were mapped again with their segmentations (Mapper::remap), not only
  /// re-integrated: super-points, graph and objects were made anew.
  bool reassociated = false;
  /// Of a remap's frames, those whose geometric segments were kept with them (not computed
  /// again from the depth).
  size_t frames_with_kept_segments = 0;
  /// A remap's frame-count instances, and of those, the ones that took an old instance's id.
  size_t instances = 0;
  size_t instances_kept = 0;  ///< (see instances)
  /// A remap's super-points, and of those, the ones that took an old super-point's id.
  size_t superpoints = 0;
  size_t superpoints_kept = 0;  ///< (see superpoints)
  /// Of the depth samples that found an instance (a super-point) in both maps, the share that
  /// found the same id in both: how much of the surface kept its object's (super-point's) id.
  double instance_surface_kept = 0.0;
  double superpoint_surface_kept = 0.0;  ///< (see instance_surface_kept)
  /// A re-integration's super-points that joined another whose surface they now coincide
  /// with (rejoinCoincidingSuperpoints()).
  size_t superpoints_rejoined = 0;
  double rejoin_s = 0.0;  ///< wall time of finding and making those merges
  /// A remap's frames: the median milliseconds of each stage (FrameStats::stageTimes, then
  /// "instance samples": the depth samples each frame keeps for the ids carried over), and the
  /// seconds spent carrying ids over at the swap. Where a repair's time goes.
  std::vector<std::pair<std::string, double>> stage_median_ms;
  double carry_over_s = 0.0;  ///< (see stage_median_ms)
};

class BinaryReader;
class FramePrefetcher;

/// The mapping core: takes (RGB-D frame, T_W_C, panoptic segmentation) and keeps a label-TSDF
/// whose voxels belong to semantically consistent super-points. No middleware inside.
class Mapper {
 public:
  /// Throws Error when the config is invalid.
  explicit Mapper(const MapperConfig& config);

  /// Integrates one frame. Validates everything first (finite rigid pose, image sizes against
  /// the intrinsics, panoptic size and ids) and throws Error with a one-line reason on bad
  /// input, leaving the map untouched.
  /// @param T_W_C camera-to-world pose of the frame (optical frame)
  /// @param panoptic the frame's 2D panoptic segmentation, or null (geometry only)
  /// @param source where the pose comes from; SLAM / odometry poses are refined against the
  ///        map first (MapperConfig::tracking_mode)
  /// @param kept the frame's geometric segments from when it was first mapped (a stored frame
  ///        mapped again), or null; used when made with this config (GeometricSegments)
  FrameStats integrate(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                       const PanopticFrame* panoptic, PoseSource source = PoseSource::kUnknown,
                       const GeometricSegments* kept = nullptr);

  /// The label-TSDF.
  const TsdfMap& map() const { return *map_; }
  /// Super-points and their frame-count labels.
  const SuperpointTracker& superpoints() const { return *tracker_; }
  /// The super-point graph as accumulated so far (III-C).
  const GraphAccumulator& graphAccumulator() const { return *graph_; }
  /// The super-point graph of the live super-points, ready for the final optimisation.
  SuperpointGraph graph() const { return graph_->graph(*map_, *tracker_); }
  /// Brings the graph's surface scan up to date with the map (SurfaceScan::refresh): what
  /// graph() would otherwise read first. Cheap when little changed since the last call; call it
  /// when there is time to spare (the live mapper does, between frames), so the final graph
  /// reads only the last few frames' blocks. Changes no result. Returns the blocks it read.
  size_t refreshSurfaceScan() const;
  /// The configuration in use.
  const MapperConfig& config() const { return config_; }
  /// Frames integrated so far.
  int64_t framesIntegrated() const { return frames_; }
  /// Votes evicted from full voxel slots so far (never silent).
  uint64_t voteEvictions() const { return vote_evictions_; }
  /// Super-points forgotten so far because no voxel voted for them any more (checked every
  /// kForgetEveryFrames frames; they would otherwise pile up in the graph on long runs).
  uint64_t superpointsForgotten() const { return superpoints_forgotten_; }
  /// Graph edges dropped so far by GraphConfig::prune_edges (in this process).
  uint64_t edgesPruned() const { return edges_pruned_; }
  /// Frames between checks for super-points without votes.
  static constexpr int64_t kForgetEveryFrames = 100;
  /// Frames between refreshSurfaceScan() calls in idle time that the live mapper and the
  /// building benchmark use by default (LiveOptions::idle_scan_every_frames).
  static constexpr int64_t kIdleScanEveryFrames = 10;
  /// The occupancy map, or null when disabled.
  const OccupancyMap* occupancy() const { return occupancy_.get(); }
  /// Every integrated frame's pose as used (refined where tracking ran), in order.
  const std::vector<StampedPose>& trajectory() const { return trajectory_; }
  /// The running correction of tracked poses: refined pose = poseCorrection() * given pose.
  const Eigen::Isometry3d& poseCorrection() const { return drift_.correction(); }
  /// Pose refinement outcomes so far, by AlignmentStatus.
  const std::array<int64_t, kAlignmentStatusCount>& trackingCounts() const {
    return tracking_counts_;
  }
  /// Whether this mapper's depth may correct poses (MapperConfig::depth_check).
  const DepthPatternMonitor& depthCheck() const { return depth_check_; }
  /// A warning when the poses given agree clearly better with the depth read another way
  /// (world-to-camera, the quaternion's scalar at the other end, cm or mm): the sender's
  /// convention is wrong. "" otherwise. The poses are used as given either way.
  std::string poseConventionWarning() const { return pose_convention_watch_.warning(); }
  /// Frames that tracking would have refined but that are integrated at their given pose
  /// because the depth check found the depth uncalibrated (FrameStats::pose_kept, and the
  /// frames refined before the verdict and integrated again as given).
  int64_t posesKeptAsGiven() const { return poses_kept_; }
  /// Most frames kept while the depth check decides (about 2.7 MB each at 640x480); a check
  /// still pending after them can no longer revert the refined frames.
  static constexpr size_t kMaxProbationFrames = 60;
  /// Frames integrated at a pose corrected by tracking.
  int64_t posesCorrected() const { return poses_corrected_; }

  /// The super-point label each pixel of the last integrated frame voted for (0 = none): what
  /// a frame store keeps so that the frame can be re-integrated at a corrected pose.
  const LabelImage& lastPixelLabels() const { return association_.pixel_labels; }
  /// The geometric segments of the last integrated frame and the key of the config that made
  /// them: what a frame store keeps so that mapping the frame again skips the depth stages.
  GeometricSegments lastGeometricSegments() const {
    return GeometricSegments{segmentation_.geometric, config_.depth_segmentation.key()};
  }
  /// Frames whose kept geometric segments integrate() took so far.
  int64_t framesWithKeptSegments() const { return frames_with_kept_segments_; }

  /// Rebuilds the label-TSDF and the occupancy map from every integrated frame at new poses: the
  /// repair after a loop closure (docs/LOOP_CLOSURE.md). Each frame votes again for the
  /// super-points it voted for (merges since are resolved as always), so super-point ids,
  /// their frame counts, co-observations and the graph survive, and objects move with their
  /// surfaces. The new maps are built aside and swapped in at the end: when a frame cannot
  /// be loaded (Error) or the progress callback abandons the work, the map is unchanged.
  /// The next updateMesh() lists every block, those without surface any more as empty.
  /// @param poses the new pose of every frame of trajectory(), same order and utimes
  /// @param load gives each frame back by its utime
  /// @param progress optional; see ReintegrationProgress
  ReintegrationStats reintegrate(const std::vector<StampedPose>& poses, const FrameLoader& load,
                                 const ReintegrationProgress& progress = {});

  /// Maps every frame again from the start at new poses, with its panoptic segmentation:
  /// segmentation, super-point association, integration, graph and occupancy, as if the
  /// frames had come with these poses (pose refinement off). The repair after a large loop
  /// closure: association under drift joins surfaces to the wrong super-points (a second pass
  /// sees the first pass's surfaces displaced), and reintegrate() keeps what association
  /// decided. Super-point ids, graph and objects are made anew; the counts of pose refinement
  /// and the frame poses' sources are kept. Built aside and swapped in at the end, as
  /// reintegrate() does: a frame that cannot be loaded or mapped (Error) or an abandoned remap
  /// leaves the map unchanged. The next updateMesh() lists every block.
  /// @param poses the new pose of every frame of trajectory(), same order and utimes
  /// @param load gives each frame back by its utime, with its segmentation
  /// @param progress optional; see ReintegrationProgress
  ReintegrationStats remap(const std::vector<StampedPose>& poses, const PanopticFrameLoader& load,
                           const ReintegrationProgress& progress = {});

  /// An empty rebuild with this mapper's configuration, for reintegrate() or for a repair that
  /// builds on another thread while this mapper keeps mapping (loop/background_repair.h).
  /// @param pool threads the rebuild integrates with (null: this mapper's own, which only the
  ///        mapping thread may then use; a remap's mapper makes its own pool)
  /// @param remap map the frames again with their segmentations (see remap()) instead of
  ///        re-integrating them
  std::unique_ptr<MapRebuild> beginRebuild(ThreadPool* pool = nullptr, bool remap = false) const;
  /// Swaps a finished rebuild in: the label-TSDF and occupancy map become the rebuild's, each
  /// frame's pose in trajectory() becomes the one it was re-integrated with, and the next
  /// updateMesh() lists every block. The running correction of tracked poses starts again from
  /// identity: the repaired map sits where the SLAM back-end's corrected poses put it, and
  /// those are what its next poses build on (docs/LOOP_CLOSURE.md). A remap's super-points,
  /// graph and their counters replace this mapper's too; its instances and super-points take
  /// the ids of the old ones they hold the surface of (carriedIds()). Throws Error, changing
  /// nothing, unless the rebuild holds exactly the frames of trajectory(), in order.
  /// @param stats if given, receives the counts of ids kept (ReintegrationStats::instances ...)
  void commitRebuild(std::unique_ptr<MapRebuild> rebuild, ReintegrationStats* stats = nullptr);
  /// Swaps in an occupancy tree built from every frame of trajectory() at `poses` (a repair's,
  /// ahead of its label-TSDF: OccupancyRebuild); the trajectory keeps its poses until the repair
  /// commits. Throws Error, changing nothing, unless `poses` has the utimes of trajectory() in
  /// order and this mapper keeps an occupancy map.
  void replaceOccupancy(std::unique_ptr<OccupancyMap> occupancy,
                        const std::vector<StampedPose>& poses);

  /// Gives the live super-points new ids: root label r becomes ids.at(r) (every super-point
  /// with a state or a vote needs one), every other label up to `size` is retired (it
  /// resolves to no super-point and is never handed out again), and super-points created
  /// afterwards start at size + 1. Votes, states, co-observations and graph evidence follow;
  /// meshes are made again. Throws Error, changing nothing, when an id is missing (for a
  /// super-point with a state, or a vote), shared or outside 1..size.
  void renumberSuperpoints(const std::map<int32_t, int32_t>& ids, int32_t size);
  /// The super-points that hold a vote or have a state (root labels, ascending).
  std::vector<int32_t> liveSuperpoints() const;

  /// The labelled mesh of the current map: marching cubes re-run only on changed blocks;
  /// per vertex the super-point (argmax of its voxel's votes, merges resolved), and the
  /// super-point's class and instance from frame counting.
  /// @param labels optimised labels (panmap-optimizer); super-points it does not name keep
  ///        their frame-count labels. Null: frame-count labels only.
  LabelledMesh extractMesh(const GraphLabels* labels = nullptr);

  /// The mesh of the blocks that changed since the previous call (marching cubes on those
  /// only), labelled as extractMesh() labels them: the periodic update of a live view, whose
  /// cost follows what the camera saw since, not the size of the map.
  /// @param labels as for extractMesh()
  MeshUpdate updateMesh(const GraphLabels* labels = nullptr);
  /// Drops the block meshes kept so that extractMesh() and updateMesh() re-run marching cubes
  /// only on changed blocks (about 0.3 GB on the 2 cm building): for the last export of a
  /// session, which no live view follows. A later extractMesh() or updateMesh() meshes the
  /// whole map again, with the same result.
  void releaseMeshCache();
  /// The same mesh as extractMesh(), for the last export of a session: drops the block
  /// meshes first (releaseMeshCache) and meshes the map from scratch block by block
  /// (marchingCubes), so the welded mesh is never held beside a copy of itself in pieces.
  /// @param labels as for extractMesh()
  LabelledMesh extractFinalMesh(const GraphLabels* labels = nullptr);

  /// Streams the whole state (config, TSDF, votes, super-points) as a map file into `sink`: a
  /// versioned header, the payload and its CRC-32, in chunks of 1 MiB (never whole in memory).
  void serialize(ByteSink* sink) const;
  /// serialize() into a byte vector.
  std::vector<uint8_t> serialize() const;
  /// Writes serialize() atomically (temporary file, fsync, rename); throws Error naming the
  /// file on failure.
  void save(const std::string& path) const;
  /// Reads a file written by save(); mapping continues exactly as if never interrupted.
  /// Throws Error naming the file when it is missing, of another version, or corrupt.
  static std::unique_ptr<Mapper> load(const std::string& path);
  /// Rebuilds a mapper from serialize()'s bytes; `what` names the source in errors (with the
  /// offset where reading failed).
  static std::unique_ptr<Mapper> deserialize(const std::vector<uint8_t>& bytes,
                                             const std::string& what);

 private:
  /// The map file's payload after its header (load() and deserialize() check the header and
  /// the checksum); throws Error naming `what` and the offset where it is malformed.
  static std::unique_ptr<Mapper> parsePayload(BinaryReader* reader, uint32_t version,
                                              const std::string& what);
  void validate(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                const PanopticFrame* panoptic) const;
  /// Throws Error (prefixed with `what`) unless `poses` are rigid and have trajectory()'s
  /// utimes, in order.
  void checkRepairPoses(const std::vector<StampedPose>& poses, const char* what) const;
  /// Takes a remap's mapper's state (commitRebuild): every part that holds its thread pool
  /// moves over with the pool; the mesher stays and is pointed at it.
  void adoptRemapped(Mapper* fresh);
  /// Builds a rebuild (a remap or a re-integration) from the prefetched frames at `poses` and
  /// commits it; `what` prefixes errors.
  ReintegrationStats rebuildFrom(const std::vector<StampedPose>& poses, FramePrefetcher* frames,
                                 bool remap, const char* what,
                                 const ReintegrationProgress& progress);
  void forgetUnvotedSuperpoints();
  /// Labels mesh vertices; `cache` holds each super-point's labels once looked up (a mesh
  /// has millions of vertices but thousands of super-points).
  MeshLabeller meshLabeller(const GraphLabels* labels,
                            absl::flat_hash_map<int32_t, SuperpointLabels>* cache) const;

  MapperConfig config_;
  std::unique_ptr<ThreadPool> pool_;
  std::unique_ptr<TsdfMap> map_;
  std::unique_ptr<PanopticGeometricSegmenter> segmenter_;
  std::unique_ptr<SuperpointTracker> tracker_;
  std::unique_ptr<ProjectiveIntegrator> integrator_;
  std::unique_ptr<IncrementalMesher> mesher_;
  std::unique_ptr<GraphAccumulator> graph_;
  std::unique_ptr<OccupancyMap> occupancy_;
  std::unique_ptr<FrameToModelAligner> aligner_;
  /// Refined pose = drift_.correction() * given pose: the last accepted correction
  /// (kPerFrame) or a smooth estimate of the input's drift (kFilter).
  DriftFilter drift_;
  std::array<int64_t, kAlignmentStatusCount> tracking_counts_{};
  DepthPatternMonitor depth_check_;
  PoseConventionWatch pose_convention_watch_;  // the given poses against the depth
  /// While the depth check is pending: every frame integrated so far, its given pose and the
  /// super-point label each pixel voted for, to integrate them again at their given poses.
  struct ProbationFrame {
    RgbdFrame frame;
    Eigen::Isometry3d T_W_C_given;
    LabelImage pixel_labels;
  };
  std::vector<ProbationFrame> probation_;
  /// probation_ holds every frame integrated (false once it overflowed, for a loaded map, or
  /// when tracking did not apply to the first frame).
  bool probation_complete_ = true;
  /// Integrates the frames of probation_ again at their given poses (depth check: uncalibrated).
  int revertProbation();
  int64_t poses_kept_ = 0;
  int64_t poses_corrected_ = 0;
  std::vector<StampedPose> trajectory_;
  int64_t frames_ = 0;
  uint64_t vote_evictions_ = 0;
  FrameSegmentation segmentation_;  // scratch, reused every frame
  RgbdFrame calibrated_frame_;      // scratch: the frame with the depth calibration applied
  int64_t frames_with_kept_segments_ = 0;
  FrameAssociation association_;      // scratch, reused every frame
  MaskEdgeFillScratch fill_scratch_;  // scratch, reused every frame
  uint64_t superpoints_forgotten_ = 0;
  uint64_t edges_pruned_ = 0;
};

}  // namespace panmap
