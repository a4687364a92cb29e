#include "panmap/graph/internal/instance_clustering.h"

#include <algorithm>
#include <map>
#include <queue>
#include <tuple>
#include <unordered_map>

#include "panmap/graph/internal/graph_check.h"

namespace panmap {
namespace internal {
namespace {

/// Evidence between two clusters: one mask (S) and two masks (P).
struct Between {
  double same = 0.0;
  double apart = 0.0;
};

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

InstanceLabels clusterInstances(const SuperpointGraph& graph, const std::vector<int32_t>& classes,
                                const OptimiserConfig& config) {
  const int n = static_cast<int>(graph.vertices.size());
  const ClassSet background = noInstanceClasses(graph);
  const VertexIndex index(graph);
  // Clusters start as single super-points; cluster k is keyed by its smallest vertex index.
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i;
  std::vector<double> observed(n, 0.0);  // sum P_nu^C of the cluster's members
  for (int i = 0; i < n; ++i) {
    const auto s = graph.vertices[i].scores.find(classes[i]);
    observed[i] = s == graph.vertices[i].scores.end() ? 0.0 : s->second;
  }
  std::vector<std::map<int, Between>> links(n);  // cluster -> neighbour cluster -> evidence
  for (const GraphEdge& e : graph.edges) {
    const int a = index(e.a), b = index(e.b);
    if (classes[a] != classes[b] || background.contains(classes[a])) continue;
    const int32_t c = classes[a];
    const auto same = e.confidences.find(c);
    const auto apart = e.separations.find(c);
    Between between;
    between.same = same == e.confidences.end() ? 0.0 : same->second;
    between.apart = apart == e.separations.end() ? 0.0 : apart->second;
    if (between.same <= 0.0 && between.apart <= 0.0) continue;
    links[a][b] = between;
    links[b][a] = between;
  }
  // A pair's entry is pushed when its link is made or changes. A join grows the coverage a
  // cluster's links need (observed only grows), so that test is repeated when an entry comes
  // out; an entry whose link changed since is stale (the link's newer entry is in the heap).
  // Re-pushing every link of a joined cluster instead filled the heap with entries stale by the
  // time they came out (docs/MAPPING.md: on a building's graph, about half of this stage).
  std::priority_queue<Candidate> heap;
  const auto affinityOf = [](const Between& between) {
    return between.same / (between.same + between.apart);
  };
  const auto covered = [&](const Between& between, int a, int b) {
    return between.same >= config.min_coverage * std::min(observed[a], observed[b]);
  };
  const auto consider = [&](int a, int b) {
    if (a > b) std::swap(a, b);
    const Between& between = links[a].at(b);
    if (!(between.same > 0.0)) return;
    const double affinity = affinityOf(between);
    if (affinity < config.join_affinity || !covered(between, a, b)) return;
    heap.push({affinity, between.same, a, b});
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
    const Between& now = links[a].at(b);
    if (now.same != top.same || affinityOf(now) != top.affinity || !covered(now, a, b)) {
      continue;  // the link changed since, or the clusters grew past what it covers
    }
    // Join b into a: links add up; each changed link gets a new entry.
    parent[b] = a;
    observed[a] += observed[b];
    links[a].erase(b);
    for (const auto& [c, between] : links[b]) {
      if (c == a) continue;
      Between& sum = links[a][c];
      sum.same += between.same;
      sum.apart += between.apart;
      Between& back = links[c][a];
      back = sum;
      links[c].erase(b);
      consider(a, c);
    }
    links[b].clear();
  }

  // Output ids: the initial instance most of a cluster's voxels carry, when no larger cluster
  // claims it; new ids otherwise.
  std::vector<int> root(n);
  for (int i = 0; i < n; ++i) {
    int r = i;
    while (parent[r] != r) r = parent[r];
    root[i] = r;
  }
  std::map<int, std::map<int32_t, int64_t>> initial;  // root -> initial id -> voxels
  std::map<int, int64_t> size;                        // root -> voxels
  for (int i = 0; i < n; ++i) {
    if (background.contains(classes[i])) continue;
    size[root[i]] += graph.vertices[i].num_voxels;
    if (graph.vertices[i].instance > 0) {
      initial[root[i]][graph.vertices[i].instance] += graph.vertices[i].num_voxels;
    }
  }
  int32_t max_initial = 0;
  for (const GraphVertex& v : graph.vertices) max_initial = std::max(max_initial, v.instance);
  std::vector<int> order;
  for (const auto& [r, voxels] : size) order.push_back(r);
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return size[x] > size[y]; });
  std::map<int, int32_t> id_of;
  std::map<int32_t, bool> taken;
  std::vector<int> fresh;
  for (int r : order) {
    int32_t best = 0;
    int64_t best_voxels = -1;
    for (const auto& [id, voxels] : initial[r]) {
      if (!taken[id] && voxels > best_voxels) best = id, best_voxels = voxels;
    }
    if (best > 0) {
      id_of[r] = best;
      taken[best] = true;
    } else {
      fresh.push_back(r);
    }
  }
  std::sort(fresh.begin(), fresh.end(), [&](int x, int y) {
    return std::make_pair(classes[x], x) < std::make_pair(classes[y], y);
  });
  int32_t next = max_initial + 1;
  for (int r : fresh) id_of[r] = next++;
  InstanceLabels out;
  out.instance.assign(n, 0);
  for (int i = 0; i < n; ++i) {
    if (!background.contains(classes[i])) out.instance[i] = id_of.at(root[i]);
  }
  return out;
}

}  // namespace internal
}  // namespace panmap
