#include "panmap/occupancy/occupancy_query.h"

#include "panmap/core/error.h"
#include "panmap/occupancy/internal/segment_walk.h"

namespace panmap {
namespace {

Occupancy stateOf(const octomap::OcTree& tree, const octomap::OcTreeKey& key) {
  const octomap::OcTreeNode* node = tree.search(key);
  if (!node) return Occupancy::kUnknown;
  return tree.isNodeOccupied(node) ? Occupancy::kOccupied : Occupancy::kFree;
}

}  // namespace

const char* occupancyName(Occupancy state) {
  switch (state) {
    case Occupancy::kFree:
      return "free";
    case Occupancy::kOccupied:
      return "occupied";
    case Occupancy::kUnknown:
      break;
  }
  return "unknown";
}

Occupancy occupancyAt(const octomap::OcTree& tree, const Eigen::Vector3d& p_W) {
  if (!p_W.allFinite()) throw Error("occupancy query point must be finite");
  octomap::OcTreeKey key;
  if (!tree.coordToKeyChecked(internal::toOctomapPoint(p_W), key)) return Occupancy::kUnknown;
  return stateOf(tree, key);
}

SegmentCheck checkSegment(const octomap::OcTree& tree, const Eigen::Vector3d& a_W,
                          const Eigen::Vector3d& b_W) {
  return internal::walkSegment(
      tree, a_W, b_W, [&tree](const octomap::OcTreeKey& key) { return stateOf(tree, key); });
}

}  // namespace panmap
