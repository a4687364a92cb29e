#pragma once

#include <cstdint>

#include "panmap/core/image.h"

namespace panmap {

/// Bounded super-point vote slots per voxel. The paper's release keeps 3 and silently drops
/// a 4th label; panmap keeps 4 and evicts the weakest, counting every eviction.
constexpr int kVoteSlots = 4;

/// One super-point label and how often it was observed in a voxel: Pi_V(L_S, V).
struct LabelVote {
  int32_t label = 0;   ///< super-point label L_S (0 = empty slot)
  uint32_t count = 0;  ///< observations
};

/// A voxel of the label-TSDF: 44 bytes.
struct Voxel {
  float sdf_m = 0.0f;   ///< truncated signed distance to the surface, metres (+ in front)
  float weight = 0.0f;  ///< integration weight, 0 = never observed
  Rgb8 color;           ///< running mean colour
  uint8_t flags = 0;    ///< reserved
  LabelVote votes[kVoteSlots];
};
static_assert(sizeof(Voxel) == 44, "keep voxels lean (<= 64 bytes with votes)");

/// Adds `n` votes for `label` (n >= 1), exactly as n calls adding one vote each would:
/// increments its slot (saturating), or fills an empty one, or evicts the weakest slot (lowest
/// count, first on ties). Returns true when a vote was evicted.
inline bool addVotes(Voxel* voxel, int32_t label, uint32_t n) {
  int empty = -1, weakest = 0;
  for (int i = 0; i < kVoteSlots; ++i) {
    LabelVote& v = voxel->votes[i];
    if (v.label == label && v.count > 0) {
      v.count = v.count > UINT32_MAX - n ? UINT32_MAX : v.count + n;
      return false;
    }
    if (v.count == 0) {
      if (empty < 0) empty = i;
    } else if (v.count < voxel->votes[weakest].count || voxel->votes[weakest].count == 0) {
      weakest = i;
    }
  }
  if (empty >= 0) {
    voxel->votes[empty] = LabelVote{label, n};
    return false;
  }
  voxel->votes[weakest] = LabelVote{label, n};
  return true;
}

/// Adds one vote for `label` (see addVotes). Returns true when a vote was evicted.
inline bool addVote(Voxel* voxel, int32_t label) { return addVotes(voxel, label, 1); }

/// Eq. 2: the voxel's super-point label, argmax of its votes after mapping every stored label
/// through `resolve` (merged super-points pool their votes). 0 when the voxel has no vote.
/// Ties go to the smaller resolved label, so the result does not depend on slot order.
template <typename Resolve>
int32_t argmaxLabel(const Voxel& voxel, const Resolve& resolve) {
  int32_t labels[kVoteSlots];
  uint64_t counts[kVoteSlots];
  int n = 0;
  for (const LabelVote& v : voxel.votes) {
    if (v.count == 0) continue;
    const int32_t label = resolve(v.label);
    int k = 0;
    while (k < n && labels[k] != label) ++k;
    if (k == n) {
      labels[n] = label;
      counts[n++] = 0;
    }
    counts[k] += v.count;
  }
  int32_t best = 0;
  uint64_t best_count = 0;
  for (int k = 0; k < n; ++k) {
    if (counts[k] > best_count || (counts[k] == best_count && labels[k] < best)) {
      best = labels[k];
      best_count = counts[k];
    }
  }
  return best;
}

}  // namespace panmap
