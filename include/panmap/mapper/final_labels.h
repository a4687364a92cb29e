#pragma once

#include <cstdint>

#include "panmap/graph/superpoint_graph.h"
#include "panmap/superpoint/superpoint_tracker.h"

namespace panmap {

/// The class and instance a super-point is reported with.
struct SuperpointLabels {
  int32_t semantic = 0;
  int32_t instance = 0;
};

/// A super-point's reported labels: the optimiser's when `labels` names it, else its
/// frame-count labels. Meshes and objects both use this, so their ids agree.
SuperpointLabels finalLabels(int32_t superpoint, const SuperpointTracker& tracker,
                             const GraphLabels* labels);

}  // namespace panmap
