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
/// frame-count labels; no instance without a thing class (0 and the stuff classes carry none).
/// Meshes and objects both use this, so their ids agree.
SuperpointLabels finalLabels(int32_t superpoint, const SuperpointTracker& tracker,
                             const GraphLabels* labels);

/// The largest frame-count instance of a graph's vertices: the optimiser's instances above it
/// are ones it made itself (kept ids are frame-count ids of the graph).
int32_t largestInitialInstance(const SuperpointGraph& graph);

/// The optimiser's labels for a graph taken from this map earlier (`graph_largest_instance`:
/// largestInitialInstance() of that graph), fitted to the map as it is now. Super-points made
/// since (new frames, or a loop-closure repair that numbered them anew) are not named and keep
/// their frame-count labels, whose instance ids may reach above the graph's; an instance the
/// optimiser made could then share an id with one of them, and the two would be reported as one
/// object. So those frame-count ids move above every id of the answer, by an offset the answer
/// alone fixes (its largest id less the graph's): the optimiser's ids stay as it gave them, and
/// stay the same at every publish of one answer, however many ids the tracker gives meanwhile.
GraphLabels fitLabelsToMap(const GraphLabels& labels, int32_t graph_largest_instance,
                           const SuperpointTracker& tracker);

}  // namespace panmap
