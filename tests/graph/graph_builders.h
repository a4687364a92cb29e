#pragma once

#include <cstdint>
#include <utility>

#include "panmap/graph/superpoint_graph.h"

namespace panmap {
namespace test {

/// A graph vertex with its voxel count and per-class scores; everything else default.
inline GraphVertex vertex(int32_t id, int32_t voxels, ClassValues scores) {
  GraphVertex v;
  v.id = id;
  v.num_voxels = voxels;
  v.scores = std::move(scores);
  return v;
}

/// A graph edge a < b with its per-class one-mask confidences; everything else default.
inline GraphEdge edge(int32_t a, int32_t b, ClassValues confidences) {
  GraphEdge e;
  e.a = a;
  e.b = b;
  e.confidences = std::move(confidences);
  return e;
}

}  // namespace test
}  // namespace panmap
