#pragma once

#include <cstdint>
#include <vector>

#include "panmap/graph/optimiser.h"
#include "panmap/graph/superpoint_graph.h"

namespace panmap {
namespace internal {

/// What classConsensus changed.
struct ClassConsensusStats {
  int groups = 0;       ///< groups of super-points of two or more classes made one
  int superpoints = 0;  ///< super-points whose class changed
};

/// One class per object (part of III-C, not in the paper): a network that names an object
/// now table, now desk leaves its super-points with different classes, each the class of the
/// views it was seen in, and no pairwise term of Eq. 9 joins two super-points that are each
/// sure of their class. Super-points of thing classes are clustered as clusterByAffinity does,
/// whatever their classes: one mask over both (sum over thing classes of P_eps^C) against two
/// masks of any classes (P_apart), with the III-D clustering's join_affinity and
/// min_coverage (observations: the sum of the thing-class scores). Every group that holds
/// two or more classes takes the class with the largest summed score over its members
/// (ties: the smaller class id). A member takes it only where its own views left it in doubt
/// (its score for that class at least consensus_min_ratio times its score for its own) and
/// where its own links to the members holding that class show one mask more often than two
/// (sum of one-mask evidence above the sum of P_apart) and more often than its links to the
/// members sharing its current class do, in rounds until nothing changes.
/// Returns the classes per vertex index; stuff and unlabelled super-points (class 0 or
/// background) are left as they are.
std::vector<int32_t> classConsensus(const SuperpointGraph& graph,
                                    const std::vector<int32_t>& classes,
                                    const OptimiserConfig& config,
                                    ClassConsensusStats* stats = nullptr);

}  // namespace internal
}  // namespace panmap
