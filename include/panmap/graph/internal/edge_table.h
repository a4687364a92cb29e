#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include <absl/container/flat_hash_map.h>
#include <absl/container/inlined_vector.h>

#include "panmap/superpoint/superpoint_tracker.h"

namespace panmap {

/// The edge confidences P_eps^C(a, b) of the super-point graph: for each pair a < b, a sum per
/// class. A flat hash table keyed by the pair, with each pair's classes in one inline slot: a
/// pair is nearly always seen under a single class, and a long run holds millions of pairs
/// (a std::map of std::maps took ~170 bytes and a cache miss per tree level for each).
/// Iteration order is the hash's, which differs between processes: everything that leaves the
/// table (graph, snapshot) is sorted by pair first, so outputs stay deterministic.
class EdgeTable {
 public:
  /// Confidence per class, sorted by class.
  using Classes = absl::InlinedVector<std::pair<int32_t, double>, 1>;
  /// The edges as an ordered map, as snapshots and map files hold them.
  using OrderedEdges = std::map<std::pair<int32_t, int32_t>, std::map<int32_t, double>>;

  /// Adds `value` to P_eps^cls(a, b); a < b, both > 0.
  void add(int32_t a, int32_t b, int32_t cls, double value) {
    addTo(&table_[key(a, b)], cls, value);
  }
  /// Hints the cache that add(a, b, ...) comes soon.
  void prefetch(int32_t a, int32_t b) const { table_.prefetch(key(a, b)); }
  /// The classes of (a, b), a < b; null if the pair was never co-observed.
  const Classes* find(int32_t a, int32_t b) const;
  /// Number of pairs.
  size_t size() const { return table_.size(); }

  /// Replays the tracker's merges in order: the removed super-point's edges move to the kept
  /// one (summed into an existing edge class by class), the edge between the two disappears.
  /// Same sums as moving them one merge at a time, with one pass over the table for all.
  void applyMerges(const std::vector<SuperpointMerge>& merges, size_t begin, size_t end);
  /// Renames both ends of every edge through `to`, which must give distinct super-points
  /// distinct ids; an edge with an end it maps to 0 or less is dropped.
  void rename(const std::function<int32_t(int32_t)>& to);
  /// Drops every edge with an end for which keep() is false.
  void keepIf(const std::function<bool(int32_t)>& keep);
  /// Drops every edge for which keep(a, b, classes) is false; returns how many.
  size_t keepPairsIf(const std::function<bool(int32_t, int32_t, const Classes&)>& keep);

  /// Calls f(a, b, classes) for every edge in (a, b) order.
  void forEachSorted(const std::function<void(int32_t, int32_t, const Classes&)>& f) const;
  /// The edges as an ordered map.
  OrderedEdges toOrdered() const;
  /// Replaces the edges.
  void assign(const OrderedEdges& edges);
  /// Estimated heap bytes: the table's slots and control bytes, and the classes of pairs with
  /// more than one.
  size_t memoryBytes() const;

 private:
  static uint64_t key(int32_t a, int32_t b) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
  }
  static int32_t first(uint64_t k) { return static_cast<int32_t>(k >> 32); }
  static int32_t second(uint64_t k) { return static_cast<int32_t>(k & 0xFFFFFFFFu); }
  /// classes[cls] += value, the class inserted at 0.0 first when absent.
  static void addTo(Classes* classes, int32_t cls, double value);

  absl::flat_hash_map<uint64_t, Classes> table_;
};

}  // namespace panmap
