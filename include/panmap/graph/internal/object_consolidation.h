#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include "panmap/graph/instance_evidence.h"
#include "panmap/graph/optimiser.h"
#include "panmap/graph/superpoint_graph.h"

namespace panmap {
namespace internal {

/// Objects out of the final instances: per vertex instance (0 = none), a confidence per
/// instance, and what happened to the fragments.
struct ConsolidatedObjects {
  std::vector<int32_t> instance;
  std::map<int32_t, float> confidence;
  std::map<int32_t, ObjectEvidence> evidence;
  int folded = 0;
  int dropped = 0;
};

/// Folds fragment instances (less surface than config.min_area_m2) into the instance of their
/// class they are most strongly linked to (P_eps^C of any member edge; a larger instance
/// before any fragment, then the strongest link, then the smaller id), so a chain of fragments
/// ends at most at one larger instance; groups that stay below the area are dropped
/// (instance 0). Then scores every remaining instance with the logistic model.
/// With consolidate off, only the scoring. Deterministic.
/// @param classes final class per vertex index; @param instances instance per vertex index
ConsolidatedObjects consolidateObjects(const SuperpointGraph& graph,
                                       const std::vector<int32_t>& classes,
                                       const std::vector<int32_t>& instances,
                                       const OptimiserConfig::Objects& config);

}  // namespace internal
}  // namespace panmap
