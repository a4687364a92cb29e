#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/frame.h"
#include "panmap/core/image.h"
#include "panmap/core/pose.h"
#include "panmap/core/thread_pool.h"
#include "panmap/map/projective_integrator.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/mapper/instance_carry_over.h"
#include "panmap/occupancy/occupancy_lane.h"
#include "panmap/occupancy/occupancy_map.h"
#include "panmap/segmentation/panoptic_geometric.h"

namespace panmap {

struct MapperConfig;
class Mapper;

/// A label-TSDF and occupancy map built again from stored frames, aside from the live map: the
/// repair after a loop closure (docs/LOOP_CLOSURE.md). Mapper::beginRebuild() makes one with
/// the mapper's configuration; add() every frame the mapper holds, in the order it integrated
/// them, each at its new pose; Mapper::commitRebuild() swaps it in. Two kinds: a
/// re-integration (each frame votes for the super-points it voted for) or a remap (each frame
/// mapped again with its segmentation by a mapper of the rebuild's own: super-points, graph
/// and objects made anew). It shares nothing with the live mapper, so one thread may build it
/// while another keeps mapping.
class MapRebuild {
 public:
  /// @param config the mapper's configuration (map, integrator and occupancy parts are used;
  ///        all of it, pose refinement off, for a remap)
  /// @param pool threads to integrate with (not owned; must outlive the rebuild); a remap's
  ///        mapper has a pool of the configured size instead, which becomes the live mapper's
  /// @param remap map the frames again with their segmentations instead of re-integrating
  MapRebuild(const MapperConfig& config, ThreadPool* pool, bool remap = false);
  ~MapRebuild();
  MapRebuild(const MapRebuild&) = delete;
  MapRebuild& operator=(const MapRebuild&) = delete;

  /// Integrates one frame at T_W_C with the super-point label each pixel voted for (null or
  /// empty: geometry only), or for a remap maps it with its segmentation (null: geometry
  /// only; the labels are not used). Throws Error naming the frame's utime when the frame,
  /// the label image or the segmentation is invalid; the rebuild is then unchanged.
  /// @param kept a remap's frame's geometric segments kept from its first mapping, or null
  void add(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C, const LabelImage* labels,
           const PanopticFrame* panoptic = nullptr, const GeometricSegments* kept = nullptr);
  /// Frames of a remap that took kept geometric segments so far.
  size_t framesWithKeptSegments() const;
  /// True for a remap.
  bool remaps() const { return static_cast<bool>(mapper_); }

  /// A remap's median milliseconds per stage over the frames added so far (FrameStats::
  /// stageTimes, then "instance samples"); empty for a re-integration.
  std::vector<std::pair<std::string, double>> stageMedians() const;

  /// The frames added so far: utime and the pose each was integrated with, in order.
  const std::vector<StampedPose>& poses() const { return poses_; }
  /// Label votes that pushed out a weaker one while building.
  uint64_t votesEvicted() const { return votes_evicted_; }
  /// The label-TSDF built so far.
  const TsdfMap& map() const;

  /// A re-integration's occupancy tree, once every frame added is in it (null for a remap or
  /// when the mapper keeps none; null after the first call). Rethrows an error the tree's
  /// thread met.
  std::unique_ptr<OccupancyMap> takeOccupancy();

 private:
  friend class Mapper;

  std::unique_ptr<MapperConfig> config_;
  ThreadPool* pool_;  // not owned
  std::unique_ptr<ProjectiveIntegrator> integrator_;
  std::unique_ptr<TsdfMap> map_;
  std::unique_ptr<OccupancyMap> occupancy_;        // null when the mapper keeps none
  std::unique_ptr<OccupancyLane> occupancy_lane_;  // fills occupancy_; after it: goes first
  std::unique_ptr<Mapper> mapper_;  // a remap's mapper (then the three above are null)
  std::vector<StampedPose> poses_;
  // A remap's depth samples of every frame, for the instance ids it carries over.
  std::vector<InstanceSampleFrame> instance_samples_;
  // A remap's stage times of every frame, by stage name in the order first seen.
  std::vector<std::pair<std::string, std::vector<double>>> stage_ms_;
  uint64_t votes_evicted_ = 0;
  RgbdFrame calibrated_;  // scratch: a frame with the depth calibration applied
};

}  // namespace panmap
