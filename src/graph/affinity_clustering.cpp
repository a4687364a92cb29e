#include "panmap/graph/internal/affinity_clustering.h"

#include <queue>
#include <tuple>
#include <utility>

namespace panmap {
namespace internal {
namespace {

/// A candidate join, ordered so that the best comes out of a max-heap first.
struct Candidate {
  double affinity;
  double same;
  int a, b;  // cluster ids (first member's vertex index), a < b
  bool operator<(const Candidate& o) const {
    return std::tie(affinity, same, o.a, o.b) < std::tie(o.affinity, o.same, a, b);
  }
};

}  // namespace

std::vector<int> clusterByAffinity(std::vector<std::map<int, LinkEvidence>> links,
                                   std::vector<double> observed, double join_affinity,
                                   double min_coverage) {
  const int n = static_cast<int>(links.size());
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i;
  // A pair's entry is pushed when its link is made or changes. A join grows the coverage a
  // cluster's links need (observed only grows), so that test is repeated when an entry comes
  // out; an entry whose link changed since is stale (the link's newer entry is in the heap).
  // Re-pushing every link of a joined cluster instead filled the heap with entries stale by the
  // time they came out (docs/MAPPING.md: on a building's graph, about half of this stage).
  std::priority_queue<Candidate> heap;
  const auto affinityOf = [](const LinkEvidence& link) {
    return link.same / (link.same + link.apart);
  };
  const auto covered = [&](const LinkEvidence& link, int a, int b) {
    return link.same >= min_coverage * std::min(observed[a], observed[b]);
  };
  const auto consider = [&](int a, int b) {
    if (a > b) std::swap(a, b);
    const LinkEvidence& link = links[a].at(b);
    if (!(link.same > 0.0)) return;
    const double affinity = affinityOf(link);
    if (affinity < join_affinity || !covered(link, a, b)) return;
    heap.push({affinity, link.same, a, b});
  };
  for (int a = 0; a < n; ++a) {
    for (const auto& [b, unused] : links[a]) {
      if (a < b) consider(a, b);
    }
  }
  while (!heap.empty()) {
    const Candidate top = heap.top();
    heap.pop();
    const int a = top.a, b = top.b;
    if (parent[a] != a || parent[b] != b) continue;  // a cluster joined another since
    const LinkEvidence& now = links[a].at(b);
    if (now.same != top.same || affinityOf(now) != top.affinity || !covered(now, a, b)) {
      continue;  // the link changed since, or the clusters grew past what it covers
    }
    // Join b into a: links add up; each changed link gets a new entry.
    parent[b] = a;
    observed[a] += observed[b];
    links[a].erase(b);
    for (const auto& [c, link] : links[b]) {
      if (c == a) continue;
      LinkEvidence& sum = links[a][c];
      sum.same += link.same;
      sum.apart += link.apart;
      links[c][a] = sum;
      links[c].erase(b);
      consider(a, c);
    }
    links[b].clear();
  }
  std::vector<int> root(n);
  for (int i = 0; i < n; ++i) {
    int r = i;
    while (parent[r] != r) r = parent[r];
    root[i] = r;
  }
  return root;
}

}  // namespace internal
}  // namespace panmap
