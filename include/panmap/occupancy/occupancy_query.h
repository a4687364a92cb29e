#pragma once

#include <cstddef>
#include <cstdint>

#include <octomap/OcTree.h>
#include <Eigen/Core>

namespace panmap {

/// What a planner may assume about a place.
enum class Occupancy : uint8_t {
  kUnknown = 0,   ///< never observed, or outside the tree's range
  kFree = 1,      ///< observed; occupancy probability below the tree's threshold
  kOccupied = 2,  ///< observed; occupancy probability at or above the threshold
};

/// "unknown", "free" or "occupied".
const char* occupancyName(Occupancy state);

/// State of the leaf containing a world point. Throws Error when the point is not finite.
/// @param p_W point in the tree's (world) frame, metres
Occupancy occupancyAt(const octomap::OcTree& tree, const Eigen::Vector3d& p_W);

/// Answer to "may a point robot move straight from A to B".
struct SegmentCheck {
  /// kFree when every cell along the segment is known free; otherwise the state (kOccupied or
  /// kUnknown) of the first cell from A that is not free. Unknown is never treated as free.
  Occupancy verdict = Occupancy::kUnknown;
  /// When not free: centre of that first non-free finest-level cell (an end point itself when
  /// it lies outside the tree's range), world frame, metres.
  Eigen::Vector3d where_W = Eigen::Vector3d::Zero();
  size_t cells_checked = 0;  ///< finest-level cells looked at, from A's cell on
};

/// Walks the finest-level cells the segment A-B passes through (OctoMap's 3D DDA,
/// computeRayKeys, plus B's own cell) from A and stops at the first cell that is not known
/// free. The segment is a line: inflating it by the robot's radius is the planner's business.
/// Throws Error when an end point is not finite or the segment spans more cells than a ray
/// may hold (about 100000).
/// @param a_W, b_W end points in the tree's (world) frame, metres
SegmentCheck checkSegment(const octomap::OcTree& tree, const Eigen::Vector3d& a_W,
                          const Eigen::Vector3d& b_W);

/// How two occupancy trees of the same resolution agree, counted in finest-level cells (a
/// pruned leaf counts as every cell it covers).
struct OccupancyAgreement {
  uint64_t known_in_both = 0;  ///< cells free or occupied in both
  uint64_t agree = 0;          ///< of those, with the same state in both
  uint64_t only_in_a = 0;      ///< known in a, unknown in b
  uint64_t only_in_b = 0;      ///< known in b, unknown in a
  /// agree / known_in_both (1 when nothing is known in both).
  double agreement() const {
    return known_in_both ? static_cast<double>(agree) / static_cast<double>(known_in_both) : 1.0;
  }
};

/// Compares two trees cell by cell, e.g. the occupancy of a repaired map against the one from
/// ground-truth poses. Throws Error when their resolutions differ.
OccupancyAgreement compareOccupancy(const octomap::OcTree& a, const octomap::OcTree& b);

}  // namespace panmap
