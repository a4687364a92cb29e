#pragma once

#include <cstddef>
#include <vector>

namespace panmap {
namespace internal {

/// A value per (vertex, label), stored label-major as one array per label. A swap move reads
/// two labels' values for the vertices holding either, which then lie in two runs of memory.
/// One array per label, not one for all: on a building's graph the single array (4.7 MB) was
/// above the 4 MiB from which panmap-mapper and panmap-optimizer take fresh pages from the
/// system for every buffer (core/memory_policy.h), so every solve paid the kernel for zeroing
/// them; a label's array (n doubles) stays below it up to half a million vertices and is
/// reused from the heap.
class LabelTable {
 public:
  /// num_vertices x num_labels values, all `value`.
  void assign(int num_vertices, int num_labels, double value) {
    rows_.assign(static_cast<size_t>(num_labels),
                 std::vector<double>(static_cast<size_t>(num_vertices), value));
  }
  /// The value of (vertex, label).
  double& operator()(int vertex, int label) { return rows_[label][vertex]; }
  double operator()(int vertex, int label) const { return rows_[label][vertex]; }
  /// The values of one label, by vertex.
  double* row(int label) { return rows_[label].data(); }
  const double* row(int label) const { return rows_[label].data(); }

 private:
  std::vector<std::vector<double>> rows_;
};

}  // namespace internal
}  // namespace panmap
