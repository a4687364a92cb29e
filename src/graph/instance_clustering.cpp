#include "panmap/graph/internal/instance_clustering.h"

#include <algorithm>
#include <map>
#include <utility>

#include "panmap/graph/internal/affinity_clustering.h"
#include "panmap/graph/internal/graph_check.h"

namespace panmap {
namespace internal {

InstanceLabels clusterInstances(const SuperpointGraph& graph, const std::vector<int32_t>& classes,
                                const OptimiserConfig& config) {
  const int n = static_cast<int>(graph.vertices.size());
  const ClassSet background = noInstanceClasses(graph);
  const VertexIndex index(graph);
  std::vector<double> observed(n, 0.0);  // sum P_nu^C of the cluster's members
  for (int i = 0; i < n; ++i) {
    const auto s = graph.vertices[i].scores.find(classes[i]);
    observed[i] = s == graph.vertices[i].scores.end() ? 0.0 : s->second;
  }
  std::vector<LinkPair> pairs;  // one mask: P_eps^C; two: P_sep^C
  pairs.reserve(graph.edges.size());
  for (const GraphEdge& e : graph.edges) {
    const int a = index(e.a), b = index(e.b);
    if (classes[a] != classes[b] || background.contains(classes[a])) continue;
    const int32_t c = classes[a];
    const auto same = e.confidences.find(c);
    const auto apart = e.separations.find(c);
    LinkEvidence link;
    link.same = same == e.confidences.end() ? 0.0 : same->second;
    link.apart = apart == e.separations.end() ? 0.0 : apart->second;
    if (link.same <= 0.0 && link.apart <= 0.0) continue;
    pairs.push_back({a, b, link});  // edges come sorted by (a, b)
  }
  const std::vector<int> root = clusterByAffinity(linksOf(n, pairs), std::move(observed),
                                                  config.join_affinity, config.min_coverage);

  // Output ids: the initial instance most of a cluster's voxels carry, when no larger cluster
  // claims it; new ids otherwise.
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
