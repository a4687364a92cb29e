#pragma once

#include <cstdint>

#include "panmap/graph/superpoint_graph.h"
#include "panmap/graph_labels_t.hpp"
#include "panmap/superpoint_graph_t.hpp"

namespace panmap {

/// PANMAP_GRAPH message of a super-point graph (exact: doubles travel as doubles).
superpoint_graph_t toMessage(const SuperpointGraph& graph, int64_t utime, int64_t request_id);
/// Graph of a PANMAP_GRAPH message. Throws Error on inconsistent ids (unsorted or duplicate
/// vertices, edges naming unknown vertices or with a >= b, array length mismatches).
SuperpointGraph fromMessage(const superpoint_graph_t& msg);

/// PANMAP_LABELS message answering request `request_id`.
graph_labels_t toMessage(const GraphLabels& labels, int64_t utime, int64_t request_id);
/// Labels of a PANMAP_LABELS message. Throws Error on length mismatches.
GraphLabels fromMessage(const graph_labels_t& msg);

}  // namespace panmap
