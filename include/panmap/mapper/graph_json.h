#pragma once

#include <string>

#include "panmap/graph/superpoint_graph.h"

namespace panmap {

/// Writes the super-point graph with its final labels as JSON, for looking at why a
/// super-point got its class or instance: per vertex its voxels, centroid, initial and final
/// labels and scores P_nu^C; per edge P_eps^C and P_sep^C. Throws Error naming the file.
void writeGraphJson(const std::string& path, const SuperpointGraph& graph,
                    const GraphLabels& labels);

}  // namespace panmap
