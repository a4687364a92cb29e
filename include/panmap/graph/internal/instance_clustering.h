#pragma once

#include <cstdint>
#include <vector>

#include "panmap/graph/internal/instance_refinement.h"
#include "panmap/graph/optimiser.h"
#include "panmap/graph/superpoint_graph.h"

namespace panmap {
namespace internal {

/// III-D as agglomerative clustering of each thing class's super-points by the network's own
/// verdicts: two clusters X, Y of class C join when, over the pairs between them, the
/// evidence of one mask outweighs the evidence of two, A(X, Y) = S / (S + P) >= join_affinity
/// (S = sum P_eps^C, P = sum P_sep^C), and S is at least min_coverage of the smaller
/// cluster's own observations (sum P_nu^C): a single merged mask among many views joins
/// nothing. Highest affinity first (average linkage: a super-point spanning two objects does
/// not chain them); ties: larger S, then the smaller first member. Instance ids: the clusters'
/// largest initial instance where it is not taken by a larger cluster, else new ids above the
/// largest initial id (ordered by class, then first member). Stuff gets 0. Deterministic.
InstanceLabels clusterInstances(const SuperpointGraph& graph, const std::vector<int32_t>& classes,
                                const OptimiserConfig& config);

}  // namespace internal
}  // namespace panmap
