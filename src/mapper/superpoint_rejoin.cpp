#include "panmap/mapper/superpoint_rejoin.h"

#include <algorithm>
#include <cstdint>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include <absl/container/flat_hash_map.h>

#include "panmap/core/error.h"
#include "panmap/map/voxel.h"

namespace panmap {
namespace {

using Pair = std::pair<int32_t, int32_t>;  // root labels, first < second

// Votes per super-point, and per pair of super-points voting in one voxel the smaller of the
// two's votes there, summed over the map.
struct Coincidence {
  std::vector<uint64_t> votes;  // by root label
  // Hashed: with a tree map the two scans of a 600-frame room took 0.42 s, on the thread
  // that maps the live frames.
  absl::flat_hash_map<Pair, uint64_t> shared;
  // The pair's shared votes over the votes of the one with fewer (0 when none are shared).
  double share(const Pair& pair) const {
    const auto it = shared.find(pair);
    if (it == shared.end()) return 0.0;
    const uint64_t smaller = std::min(votes[pair.first], votes[pair.second]);
    return static_cast<double>(it->second) / static_cast<double>(smaller);
  }
};

Coincidence countVotes(const TsdfMap& map, const LabelRegistry& labels) {
  Coincidence c;
  c.votes.assign(static_cast<size_t>(labels.size()) + 1, 0);
  for (const auto& block : map.blocks()) {
    for (int i = 0; i < kBlockVoxels; ++i) {
      const VoxelVotes* voxel = block->votes(i);
      if (!voxel) continue;
      int32_t roots[kVoteSlots];
      uint64_t counts[kVoteSlots];
      int n = 0;
      for (const LabelVote& v : voxel->slots) {
        if (v.count == 0) continue;
        const int32_t root = labels.resolve(v.label);
        if (root <= 0) continue;  // no live super-point
        int k = 0;
        while (k < n && roots[k] != root) ++k;
        if (k == n) roots[n] = root, counts[n++] = 0;
        counts[k] += v.count;
      }
      for (int k = 0; k < n; ++k) {
        c.votes[roots[k]] += counts[k];
        for (int j = k + 1; j < n; ++j) {
          c.shared[std::minmax(roots[k], roots[j])] += std::min(counts[k], counts[j]);
        }
      }
    }
  }
  return c;
}

}  // namespace

size_t rejoinCoincidingSuperpoints(const TsdfMap& map, const TsdfMap* before,
                                   SuperpointTracker* tracker, double min_share) {
  if (!tracker) throw Error("rejoinCoincidingSuperpoints: no tracker");
  const LabelRegistry& labels = tracker->labels();
  const Coincidence after = countVotes(map, labels);
  Coincidence old;
  if (before) old = countVotes(*before, labels);
  // (shared votes, negated for the sort; pair; share)
  std::vector<std::tuple<int64_t, Pair, double>> pairs;
  for (const auto& [pair, shared] : after.shared) {
    const double share = after.share(pair);
    if (share < min_share || (before && old.share(pair) >= min_share)) continue;
    pairs.emplace_back(-static_cast<int64_t>(shared), pair, share);
  }
  // The pairs sharing most votes first: the surfaces seen twice, before the fragments along
  // them, whose merges would bring their own apart counts to the pair. Ties in label order.
  std::sort(pairs.begin(), pairs.end());
  // Each super-point rejoins at most one other: a super-point that association gave the
  // surfaces of two neighbours under drift coincides with both, and joining it to both would
  // join the neighbours (box room 4: a row of three cabinets as one object).
  std::set<int32_t> taken;
  size_t merges = 0;
  for (const auto& [shared, pair, share] : pairs) {
    if (taken.count(pair.first) || taken.count(pair.second)) continue;
    if (!tracker->rejoin(pair.first, pair.second, share)) continue;
    taken.insert(pair.first);
    taken.insert(pair.second);
    ++merges;
  }
  return merges;
}

}  // namespace panmap
