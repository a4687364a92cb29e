#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/calibration/depth_calibration.h"
#include "panmap/core/camera.h"
#include "panmap/core/frame.h"
#include "panmap/core/pose.h"
#include "panmap/core/thread_pool.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/superpoint/superpoint_tracker.h"

namespace panmap {

/// A repair that maps the frames again makes its instances and super-points anew, numbered in
/// the order it meets them, while a planner knows the objects (and the optimiser the
/// super-points) by the ids they were given before. Depth samples of
/// the repaired frames say which old instance and which new one hold the same surface:
/// each sample is looked up in the old map at the frame's old pose and in the new map at its
/// new pose (the same pixel sees the same surface in both), so the match does not depend on how
/// far the correction moved anything.
struct InstanceSampleFrame {
  /// One pixel with a depth measurement.
  struct Sample {
    uint16_t u = 0;    ///< column, pixels
    uint16_t v = 0;    ///< row, pixels
    float d_m = 0.0f;  ///< depth, metres (> 0)
  };
  size_t index = 0;  ///< the frame's place in the trajectory (and in the repair)
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();  ///< its pose in the new map
  PinholeCamera camera;
  std::vector<Sample> samples;
};

/// Every frame of a repair is sampled on a grid of this many pixels (a 640x480 frame: up to 1,200
/// samples, one every 5.6 cm at 2 m), so that each part of the trajectory counts alike and a
/// small object gets the 3 samples a pairing needs (a 32 px grid left more of them a new id).
constexpr int kInstanceSampleStepPx = 16;

/// The pixels with depth of `frame` on a grid of `step_px` (>= 1) pixels, as frame `index` of a
/// repair mapped at T_W_C.
/// @param calibration the depth calibration the frame was mapped with, if any: each sampled
///        reading is corrected as the mapper corrected the whole frame, so the samples see the
///        surfaces the maps hold
InstanceSampleFrame sampleFrame(const RgbdFrame& frame, size_t index,
                                const Eigen::Isometry3d& T_W_C, int step_px,
                                const DepthCalibration* calibration = nullptr);

/// Samples per (new id, old id) pair: how much surface the two share.
using IdOverlap = std::map<std::pair<int32_t, int32_t>, int>;
/// Samples per (new instance, old instance) pair.
using InstanceOverlap = IdOverlap;

/// What the samples of a repair found in both maps.
struct CarryOverlap {
  IdOverlap instances;    ///< per (new, old) frame-count instance
  IdOverlap superpoints;  ///< per (new, old) super-point (root labels)
};

/// Looks every sample up in both maps: in the old one at trajectory_old[index] with the old
/// super-points, in the new one at the frame's new pose with the new super-points; counts the
/// samples whose voxel belongs to a super-point in both, and to a (frame-count) instance in
/// both. Neither map may change meanwhile. Throws Error when a frame's index is outside
/// trajectory_old.
/// @param pool threads to share the frames among (null: this thread only; same result)
CarryOverlap countCarryOverlap(const std::vector<InstanceSampleFrame>& frames,
                               const std::vector<StampedPose>& trajectory_old,
                               const TsdfMap& old_map, const SuperpointTracker& old_tracker,
                               const TsdfMap& new_map, const SuperpointTracker& new_tracker,
                               ThreadPool* pool = nullptr);

/// New ids for `new_ids` (the ids of a repaired map's instances or super-points, ascending).
/// Pairs are taken by the samples they share, most first (ties: smaller new id, then smaller
/// old id), each old and each new id at most once, and only when they share at least 3 samples
/// and a fifth of the new id's samples that found an old one: that new id takes the old id.
/// Every other one gets an id no instance or super-point had before, from old_next up, in
/// ascending order, so an id never names another object or surface than it did.
/// @param old_next the first id the old map never handed out (old ids are below it)
/// @param next receives the first id free after the renumbering
std::map<int32_t, int32_t> carriedIds(const IdOverlap& overlap, const std::vector<int32_t>& new_ids,
                                      int32_t old_next, int32_t* next);

/// carriedIds() for the instances 1 .. new_next_instance - 1 of a repaired map, the old map's
/// being below old_next_instance (SuperpointTracker::renumberInstances()).
std::map<int32_t, int32_t> carriedInstanceIds(const InstanceOverlap& overlap,
                                              int32_t new_next_instance, int32_t old_next_instance,
                                              int32_t* next_instance);

}  // namespace panmap
