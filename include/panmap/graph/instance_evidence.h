#pragma once

#include <cstdint>
#include <vector>

#include "panmap/graph/superpoint_graph.h"

namespace panmap {

/// What the super-point graph says for one instance of the final labelling: how much of the
/// map it covers and how often, how confidently and how consistently the network saw it.
struct InstanceEvidence {
  int32_t instance = 0;     ///< instance id (> 0)
  int32_t class_id = 0;     ///< its class C
  int32_t superpoints = 0;  ///< member super-points
  int64_t voxels = 0;       ///< sum of the members' voxels
  /// sum over members of P_nu^C (Eq. 5): score-weighted voxel observations as class C.
  double score = 0.0;
  double score_all = 0.0;   ///< the same over every class
  double inner_link = 0.0;  ///< P_O (Eq. 10): the strongest P_eps^C between two members
  double outer_link = 0.0;  ///< the strongest P_eps^C from a member to another instance of C
  /// score / voxels: confident observations per voxel, about the number of frames that saw
  /// the instance under a mask of its class, weighted by the masks' scores.
  double support() const { return voxels > 0 ? score / static_cast<double>(voxels) : 0.0; }
  /// score / score_all: the share of its observations that said class C.
  double classShare() const { return score_all > 0.0 ? score / score_all : 0.0; }
};

/// The evidence of every instance (> 0) of a labelling of `graph`: `classes` and `instances`
/// per vertex (graph order). Sorted by instance id. Throws Error when the lengths differ.
std::vector<InstanceEvidence> instanceEvidence(const SuperpointGraph& graph,
                                               const std::vector<int32_t>& classes,
                                               const std::vector<int32_t>& instances);

}  // namespace panmap
