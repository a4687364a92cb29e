#include "panmap/graph/internal/graph_check.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "panmap/core/error.h"

namespace panmap {
namespace internal {
namespace {

// `field` names the map only when a value is bad: building the name for each of a building's
// 300k edges took 40 ms, a tenth of the final optimisation.
template <typename Field>
void checkValues(const ClassValues& values, const Field& field, const char* name) {
  for (const auto& [c, v] : values) {
    if (!std::isfinite(v) || v < 0.0) {
      throw Error(field() + name + "[" + std::to_string(c) + "]: " + std::to_string(v) +
                  " (must be finite, >= 0)");
    }
  }
}

}  // namespace

constexpr int32_t kTableSize = 1 << 16;
constexpr int32_t kMaxInitialInstance = 1 << 30;

void checkGraph(const SuperpointGraph& graph) {
  if (graph.classes.empty() && !graph.vertices.empty()) {
    throw Error("SuperpointGraph.classes: empty for a graph of " +
                std::to_string(graph.vertices.size()) + " vertices");
  }
  if (!(std::isfinite(graph.voxel_size_m) && graph.voxel_size_m >= 0.0)) {
    throw Error("SuperpointGraph.voxel_size_m: " + std::to_string(graph.voxel_size_m) +
                " (must be finite, >= 0; 0 = unknown)");
  }
  for (size_t i = 0; i < graph.vertices.size(); ++i) {
    const GraphVertex& v = graph.vertices[i];
    auto field = [i] { return "SuperpointGraph.vertices[" + std::to_string(i) + "]"; };
    if (v.id <= 0) throw Error(field() + ".id: " + std::to_string(v.id) + " (must be > 0)");
    if (i > 0 && v.id <= graph.vertices[i - 1].id) {
      throw Error(field() + ".id: " + std::to_string(v.id) + " not above the previous id " +
                  std::to_string(graph.vertices[i - 1].id));
    }
    // Refinement numbers new instances above the largest initial one: leave it room (an
    // initial instance of INT32_MAX overflowed, found by fuzz/fuzz_lcm_messages).
    if (v.instance < 0 || v.instance >= kMaxInitialInstance) {
      throw Error(field() + ".instance: " + std::to_string(v.instance) + " (must be in [0, 2^30))");
    }
    if (!(v.void_share >= 0.0 && v.void_share <= 1.0)) {
      throw Error(field() + ".void_share: " + std::to_string(v.void_share) +
                  " (must be in [0, 1])");
    }
    // Sizes weight the energy and centroids place objects: an optimiser fed a graph from the
    // bus answered one of -5 voxels and NaN centroids as if they were real.
    if (v.num_voxels < 0) {
      throw Error(field() + ".num_voxels: " + std::to_string(v.num_voxels) + " (must be >= 0)");
    }
    if (!v.centroid.allFinite()) throw Error(field() + ".centroid: not finite");
    checkValues(v.scores, field, ".scores");
  }
  const VertexIndex index(graph);
  for (size_t i = 0; i < graph.edges.size(); ++i) {
    const GraphEdge& e = graph.edges[i];
    auto field = [i] { return "SuperpointGraph.edges[" + std::to_string(i) + "]"; };
    if (e.a >= e.b) {
      throw Error(field() + ": a = " + std::to_string(e.a) +
                  " not below b = " + std::to_string(e.b));
    }
    if (index(e.a) < 0) throw Error(field() + ".a: unknown vertex " + std::to_string(e.a));
    if (index(e.b) < 0) throw Error(field() + ".b: unknown vertex " + std::to_string(e.b));
    if (i > 0) {
      const GraphEdge& p = graph.edges[i - 1];
      if (std::make_pair(e.a, e.b) <= std::make_pair(p.a, p.b)) {
        throw Error(field() + ": (" + std::to_string(e.a) + ", " + std::to_string(e.b) +
                    ") not above the previous edge (sorted by (a, b), no duplicates)");
      }
    }
    checkValues(e.confidences, field, ".confidences");
    checkValues(e.separations, field, ".separations");
    if (!(std::isfinite(e.apart) && e.apart >= 0.0)) {
      throw Error(field() + ".apart: " + std::to_string(e.apart) + " (must be finite, >= 0)");
    }
  }
}

VertexIndex::VertexIndex(const SuperpointGraph& graph) {
  const std::vector<GraphVertex>& vertices = graph.vertices;
  if (vertices.empty()) return;
  // Ids keep growing over a long run while forgotten super-points leave the graph: a building's
  // final graph held 21,723 vertices with ids up to 90,477, just past the 4 slots per vertex
  // the table was once limited to, and searching the vertices took a third of its final
  // optimisation (docs/PERFORMANCE.md). A table of up to 32 slots per vertex (4 bytes each)
  // costs far less than the searches it saves: every edge's two ends, in every stage.
  const int64_t max_id = vertices.back().id;
  if (max_id <= 32 * static_cast<int64_t>(vertices.size()) + 1024) {
    table_.assign(max_id + 1, -1);
    for (size_t i = 0; i < vertices.size(); ++i) {
      if (vertices[i].id >= 0) table_[vertices[i].id] = static_cast<int>(i);
    }
    return;
  }
  // Else a search over the ids alone: contiguous, unlike the vertices they are read from.
  ids_.reserve(vertices.size());
  for (const GraphVertex& v : vertices) ids_.push_back(v.id);
}

int VertexIndex::operator()(int32_t id) const {
  if (!table_.empty()) {
    return id >= 0 && id < static_cast<int32_t>(table_.size()) ? table_[id] : -1;
  }
  const auto it = std::lower_bound(ids_.begin(), ids_.end(), id);
  if (it == ids_.end() || *it != id) return -1;
  return static_cast<int>(it - ids_.begin());
}

ClassSet::ClassSet(std::vector<int32_t> classes) : sorted_(std::move(classes)) {
  std::sort(sorted_.begin(), sorted_.end());
  sorted_.erase(std::unique(sorted_.begin(), sorted_.end()), sorted_.end());
  for (int32_t c : sorted_) {
    if (c < 0 || c >= kTableSize) {
      flags_complete_ = false;
      continue;
    }
    if (c >= static_cast<int32_t>(flags_.size())) flags_.resize(c + 1, 0);
    flags_[c] = 1;
  }
}

bool ClassSet::containsSorted(const std::vector<int32_t>& sorted, int32_t value) {
  return std::binary_search(sorted.begin(), sorted.end(), value);
}

ClassSet noInstanceClasses(const SuperpointGraph& graph) {
  std::vector<int32_t> classes = graph.background;
  classes.push_back(0);
  return ClassSet(std::move(classes));
}

}  // namespace internal
}  // namespace panmap
