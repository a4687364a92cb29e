#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include "panmap/graph/optimiser.h"
#include "panmap/graph/superpoint_graph.h"

namespace panmap {
namespace internal {

/// Instances of all vertices and the confidence of each instance.
struct InstanceLabels {
  std::vector<int32_t> instance;        ///< per vertex index, 0 = none (stuff)
  std::map<int32_t, float> confidence;  ///< instance id -> P_O / max P_O in [0, 1]
};

/// III-D instance refinement of a checked graph given the final class of every vertex (per
/// vertex index). See instance_refinement.cpp for the rules.
InstanceLabels refineInstances(const SuperpointGraph& graph, const std::vector<int32_t>& classes,
                               const OptimiserConfig& config);

/// The initial instances (refinement off): vertex.instance for thing classes, 0 for stuff,
/// with the same confidences as refineInstances computes.
InstanceLabels initialInstances(const SuperpointGraph& graph, const std::vector<int32_t>& classes);

}  // namespace internal
}  // namespace panmap
