#pragma once

#include <vector>

#include <boost/container/flat_map.hpp>

namespace panmap {
namespace internal {

/// Evidence between two clusters: of one object (seen under one mask) and of two.
struct LinkEvidence {
  double same = 0.0;
  double apart = 0.0;
};

/// One vertex's links, by the other end's index. A flat map (one sorted array): a join
/// rewrites a cluster's links in one pass, where std::map's node per link made the clustering
/// allocation-bound on a building's graph (docs/MAPPING.md, III-D).
using Links = boost::container::flat_map<int, LinkEvidence>;

/// One link between vertices a and b of a graph (indices).
struct LinkPair {
  int a;
  int b;
  LinkEvidence evidence;
};

/// The links of n vertices, both directions of every pair: `pairs` sorted by (a, b), each pair
/// once, so every vertex's list grows at its end. Each list is sized once (counted first): a
/// list grown entry by entry reallocates several times, tens of thousands of lists a graph.
std::vector<Links> linksOf(int n, const std::vector<LinkPair>& pairs);

/// Agglomerative clustering by the network's verdicts (average linkage): clusters X, Y join
/// when same / (same + apart) over the pairs between them reaches `join_affinity` and `same`
/// is at least `min_coverage` of the smaller cluster's `observed`; highest affinity first,
/// ties by larger `same`, then the smaller first member. `links[i]` holds vertex i's links
/// (symmetric). Returns each vertex's cluster, named by a member's index. Deterministic.
std::vector<int> clusterByAffinity(std::vector<Links> links, std::vector<double> observed,
                                   double join_affinity, double min_coverage);

}  // namespace internal
}  // namespace panmap
