#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include <octomap/OcTree.h>
#include <Eigen/Core>

#include "panmap/core/error.h"
#include "panmap/occupancy/occupancy_query.h"

namespace panmap {
namespace internal {

/// A world point as OctoMap's float point (queries and the exported tree agree on cells
/// because both go through this conversion and the tree's coordToKey).
inline octomap::point3d toOctomapPoint(const Eigen::Vector3d& p) {
  return octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()),
                          static_cast<float>(p.z()));
}

/// checkSegment over any cell store: `geometry` supplies the key arithmetic and OctoMap's
/// DDA (only its resolution matters), `state(key)` the occupancy of a finest-level cell.
template <typename StateOfKey>
SegmentCheck walkSegment(const octomap::OcTree& geometry, const Eigen::Vector3d& a_W,
                         const Eigen::Vector3d& b_W, const StateOfKey& state) {
  // OctoMap's KeyRay holds at most 100000 keys and does not check in release builds.
  constexpr long kMaxSegmentCells = 90000;
  if (!a_W.allFinite() || !b_W.allFinite()) throw Error("segment end points must be finite");
  SegmentCheck out;
  octomap::OcTreeKey key_a, key_b;
  if (!geometry.coordToKeyChecked(toOctomapPoint(a_W), key_a)) {
    out.where_W = a_W;
    return out;
  }
  // B beyond the tree's range (+-2^15 cells): the segment is walked up to the range's edge,
  // and found free that far it meets unknown there, not at B (a planner was told a ray was
  // clear for two kilometres when its far end lay out of range).
  Eigen::Vector3d end_W = b_W;
  bool clipped = false;
  if (!geometry.coordToKeyChecked(toOctomapPoint(b_W), key_b)) {
    const double limit = (32768.0 - 1.0) * geometry.getResolution();
    double t = 1.0;
    const Eigen::Vector3d d = b_W - a_W;
    for (int i = 0; i < 3; ++i) {
      if (std::abs(b_W[i]) > limit && d[i] != 0.0) {
        t = std::min(t, ((d[i] > 0 ? limit : -limit) - a_W[i]) / d[i]);
      }
    }
    end_W = a_W + std::max(0.0, t) * d;
    clipped = true;
    if (!geometry.coordToKeyChecked(toOctomapPoint(end_W), key_b)) {
      out.where_W = end_W;
      return out;
    }
  }
  long steps = 0;
  for (int i = 0; i < 3; ++i) steps += std::labs(static_cast<long>(key_a[i]) - key_b[i]);
  if (steps > kMaxSegmentCells) {
    throw Error("segment crosses " + std::to_string(steps) + " cells, more than " +
                std::to_string(kMaxSegmentCells) + " (split it)");
  }
  // A ray buffer is 600 kB: allocate it once per thread, not per query.
  thread_local octomap::KeyRay ray;
  geometry.computeRayKeys(toOctomapPoint(a_W), toOctomapPoint(end_W), ray);  // A's cell .. B's
  auto visit = [&](const octomap::OcTreeKey& key) {                          // (exclusive)
    ++out.cells_checked;
    const Occupancy s = state(key);
    if (s == Occupancy::kFree) return true;
    out.verdict = s;
    const octomap::point3d c = geometry.keyToCoord(key);
    out.where_W = Eigen::Vector3d(c.x(), c.y(), c.z());
    return false;
  };
  for (const octomap::OcTreeKey& key : ray) {
    if (!visit(key)) return out;
  }
  if (!visit(key_b)) return out;
  if (clipped) {
    out.where_W = end_W;  // free up to the range's edge, unknown beyond it
    return out;
  }
  out.verdict = Occupancy::kFree;
  return out;
}

}  // namespace internal
}  // namespace panmap
