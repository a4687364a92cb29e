#include "panmap/graph/internal/affinity_clustering.h"

#include <algorithm>
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

std::vector<Links> linksOf(int n, const std::vector<LinkPair>& pairs) {
  std::vector<int> degree(n, 0);
  for (const LinkPair& p : pairs) ++degree[p.a], ++degree[p.b];
  std::vector<Links> links(n);
  for (int i = 0; i < n; ++i) links[i].reserve(degree[i]);
  for (const LinkPair& p : pairs) {
    links[p.a].emplace_hint(links[p.a].end(), p.b, p.evidence);
    links[p.b].emplace_hint(links[p.b].end(), p.a, p.evidence);
  }
  return links;
}

std::vector<int> clusterByAffinity(std::vector<Links> links, std::vector<double> observed,
                                   double join_affinity, double min_coverage) {
  const int n = static_cast<int>(links.size());
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i;
  // A pair's entry is pushed when its link is made or changes. A join grows the coverage a
  // cluster's links need (observed only grows), so that test is repeated when an entry comes
  // out; an entry whose link changed since is stale (the link's newer entry is in the heap).
  // Re-pushing every link of a joined cluster instead filled the heap with entries stale by the
  // time they came out (docs/MAPPING.md: on a building's graph, about half of this stage).
  std::vector<Candidate> heap;  // a max-heap (std::push_heap / pop_heap)
  std::vector<std::pair<int, LinkEvidence>> merged;
  const auto affinityOf = [](const LinkEvidence& link) {
    return link.same / (link.same + link.apart);
  };
  const auto covered = [&](const LinkEvidence& link, int a, int b) {
    return link.same >= min_coverage * std::min(observed[a], observed[b]);
  };
  // Appends the pair's entry when its link qualifies; a < b.
  const auto candidate = [&](int a, int b, const LinkEvidence& link) {
    if (!(link.same > 0.0)) return false;
    const double affinity = affinityOf(link);
    if (affinity < join_affinity || !covered(link, a, b)) return false;
    heap.push_back({affinity, link.same, a, b});
    return true;
  };
  for (int a = 0; a < n; ++a) {
    for (const auto& [b, link] : links[a]) {
      if (a < b) candidate(a, b, link);
    }
  }
  // The first entries, one per link, are sorted once, best last, and taken from the back; the
  // heap holds only the entries of links that joins changed. Each step takes the better of the
  // two fronts, so entries come out in a single heap's order, with fewer sift operations over a
  // smaller heap (the plain algorithm's order: test JoinsInTheOrderOfThePlainAlgorithm).
  std::vector<Candidate> initial;
  initial.swap(heap);
  std::sort(initial.begin(), initial.end());
  while (!initial.empty() || !heap.empty()) {
    Candidate top;
    if (heap.empty() || (!initial.empty() && heap.front() < initial.back())) {
      top = initial.back();
      initial.pop_back();
    } else {
      std::pop_heap(heap.begin(), heap.end());
      top = heap.back();
      heap.pop_back();
    }
    const int a = top.a, b = top.b;
    if (parent[a] != a || parent[b] != b) continue;  // a cluster joined another since
    const LinkEvidence& now = links[a].at(b);
    if (now.same != top.same || affinityOf(now) != top.affinity || !covered(now, a, b)) {
      continue;  // the link changed since, or the clusters grew past what it covers
    }
    // Join b into a: links add up (one merge of the two sorted lists); each changed link
    // gets a new entry.
    parent[b] = a;
    observed[a] += observed[b];
    merged.clear();
    merged.reserve(links[a].size() + links[b].size());
    auto ia = links[a].begin(), ib = links[b].begin();
    const auto ea = links[a].end(), eb = links[b].end();
    while (ia != ea || ib != eb) {
      if (ib == eb || (ia != ea && ia->first < ib->first)) {
        if (ia->first != b) merged.push_back(*ia);
        ++ia;
      } else if (ia == ea || ib->first < ia->first) {
        if (ib->first != a) merged.push_back(*ib);
        ++ib;
      } else {
        merged.emplace_back(ia->first, LinkEvidence{ia->second.same + ib->second.same,
                                                    ia->second.apart + ib->second.apart});
        ++ia, ++ib;
      }
    }
    links[a].clear();
    links[a].insert(boost::container::ordered_unique_range, merged.begin(), merged.end());
    for (const auto& [c, unused] : links[b]) {
      if (c == a) continue;
      Links& of_c = links[c];
      of_c.erase(b);
      const LinkEvidence& sum = links[a].at(c);
      of_c[a] = sum;
      if (candidate(std::min(a, c), std::max(a, c), sum)) {
        std::push_heap(heap.begin(), heap.end());
      }
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
