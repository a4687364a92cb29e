#pragma once

#include <cstdint>
#include <vector>

#include "panmap/graph/superpoint_graph.h"

namespace panmap {
namespace internal {

/// Checks the invariants the optimiser relies on; throws Error naming the bad field:
/// vertex ids > 0 and strictly ascending, edges with a < b naming known vertices and strictly
/// ascending by (a, b), finite non-negative scores and confidences, classes non-empty when
/// there are vertices.
void checkGraph(const SuperpointGraph& graph);

/// Super-point id -> index in graph.vertices (sorted by id): a table when the ids are dense
/// enough, else a binary search over the ids alone.
class VertexIndex {
 public:
  /// @param graph vertices sorted by id (checked by checkGraph).
  explicit VertexIndex(const SuperpointGraph& graph);
  /// Index of the vertex with this id, -1 if absent.
  int operator()(int32_t id) const;

 private:
  std::vector<int> table_;    ///< id -> index (-1 none), empty when the ids are too sparse
  std::vector<int32_t> ids_;  ///< the vertices' ids in order, when there is no table
};

/// A set of class ids with constant-time membership for the usual small ids.
class ClassSet {
 public:
  /// Sorts and deduplicates `classes`.
  explicit ClassSet(std::vector<int32_t> classes);
  /// True when c is in the set.
  bool contains(int32_t c) const {
    if (c >= 0 && c < static_cast<int32_t>(flags_.size())) return flags_[c] != 0;
    return !flags_complete_ && containsSorted(sorted_, c);
  }
  /// The classes, ascending.
  const std::vector<int32_t>& sorted() const { return sorted_; }

 private:
  static bool containsSorted(const std::vector<int32_t>& sorted, int32_t value);
  std::vector<int32_t> sorted_;
  std::vector<char> flags_;     ///< flags for ids in [0, kTableSize)
  bool flags_complete_ = true;  ///< all classes are in [0, kTableSize)
};

/// The classes whose super-points get no instance: the graph's background C_0 (stuff) and
/// class 0, the super-points left unlabelled (OptimiserConfig::max_void_share).
ClassSet noInstanceClasses(const SuperpointGraph& graph);

}  // namespace internal
}  // namespace panmap
