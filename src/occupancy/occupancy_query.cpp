#include "panmap/occupancy/occupancy_query.h"

#include <string>

#include "panmap/core/error.h"
#include "panmap/occupancy/internal/segment_walk.h"

namespace panmap {
namespace {

Occupancy stateOf(const octomap::OcTree& tree, const octomap::OcTreeKey& key) {
  const octomap::OcTreeNode* node = tree.search(key);
  if (!node) return Occupancy::kUnknown;
  return tree.isNodeOccupied(node) ? Occupancy::kOccupied : Occupancy::kFree;
}

// Calls fn(key, state) for every finest-level cell the leaves of `tree` cover.
template <typename Fn>
void forEachKnownCell(const octomap::OcTree& tree, Fn fn) {
  const unsigned max_depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const Occupancy state = tree.isNodeOccupied(*it) ? Occupancy::kOccupied : Occupancy::kFree;
    const octomap::OcTreeKey base = it.getIndexKey();  // the leaf's lowest corner cell
    const unsigned side = 1u << (max_depth - it.getDepth());
    octomap::OcTreeKey key;
    for (unsigned x = 0; x < side; ++x) {
      for (unsigned y = 0; y < side; ++y) {
        for (unsigned z = 0; z < side; ++z) {
          key[0] = static_cast<octomap::key_type>(base[0] + x);
          key[1] = static_cast<octomap::key_type>(base[1] + y);
          key[2] = static_cast<octomap::key_type>(base[2] + z);
          fn(key, state);
        }
      }
    }
  }
}

}  // namespace

OccupancyAgreement compareOccupancy(const octomap::OcTree& a, const octomap::OcTree& b) {
  if (a.getResolution() != b.getResolution()) {
    throw Error("occupancy trees of different resolutions (" + std::to_string(a.getResolution()) +
                " and " + std::to_string(b.getResolution()) + " m)");
  }
  OccupancyAgreement out;
  forEachKnownCell(a, [&](const octomap::OcTreeKey& key, Occupancy state) {
    const Occupancy other = stateOf(b, key);
    if (other == Occupancy::kUnknown) {
      ++out.only_in_a;
      return;
    }
    ++out.known_in_both;
    out.agree += other == state;
  });
  forEachKnownCell(b, [&](const octomap::OcTreeKey& key, Occupancy) {
    out.only_in_b += stateOf(a, key) == Occupancy::kUnknown;
  });
  return out;
}

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
