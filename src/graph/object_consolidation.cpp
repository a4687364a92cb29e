#include "panmap/graph/internal/object_consolidation.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

#include "panmap/graph/internal/graph_check.h"
#include "panmap/graph/object_confidence.h"

namespace panmap {
namespace internal {
namespace {

int findRoot(std::vector<int>& parent, int k) {
  while (parent[k] != k) k = parent[k] = parent[parent[k]];
  return k;
}

double areaOf(int64_t voxels, double voxel_size_m) {
  return static_cast<double>(voxels) * voxel_size_m * voxel_size_m;
}

}  // namespace

ConsolidatedObjects consolidateObjects(const SuperpointGraph& graph,
                                       const std::vector<int32_t>& classes,
                                       const std::vector<int32_t>& instances,
                                       const OptimiserConfig::Objects& config) {
  ConsolidatedObjects out;
  out.instance = instances;
  const double voxel_m = graph.voxel_size_m;
  if (config.consolidate && voxel_m > 0.0) {
    const std::vector<InstanceEvidence> evidence = instanceEvidence(graph, classes, instances);
    const int n = static_cast<int>(evidence.size());
    std::map<int32_t, int> slot;  // instance id -> index into evidence
    for (int k = 0; k < n; ++k) slot[evidence[k].instance] = k;
    std::vector<bool> fragment(n);
    for (int k = 0; k < n; ++k) {
      fragment[k] = areaOf(evidence[k].voxels, voxel_m) < config.min_area_m2;
    }
    // Each fragment's strongest same-class link to another instance: to a larger instance if
    // it has any such link (a fragment belongs to an object), else to another fragment.
    // (larger?, link, -target) compares lexicographically; target 0 = none.
    std::vector<std::tuple<bool, double, int32_t>> best(n, {false, 0.0, 0});
    const VertexIndex index(graph);
    for (const GraphEdge& edge : graph.edges) {
      const int a = index(edge.a), b = index(edge.b);
      const int32_t ia = instances[a], ib = instances[b];
      if (ia <= 0 || ib <= 0 || ia == ib || classes[a] != classes[b]) continue;
      const auto c = edge.confidences.find(classes[a]);
      if (c == edge.confidences.end() || !(c->second > 0.0)) continue;
      for (const auto& [from, to] : {std::make_pair(ia, ib), std::make_pair(ib, ia)}) {
        if (!fragment[slot[from]]) continue;
        const std::tuple<bool, double, int32_t> candidate{!fragment[slot[to]], c->second, -to};
        auto& current = best[slot[from]];
        if (std::get<2>(current) == 0 || candidate > current) current = candidate;
      }
    }
    // Every fragment points at one instance and larger ones at none: a group holds at most
    // one larger instance.
    std::vector<int> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    for (int k = 0; k < n; ++k) {
      const int32_t target = -std::get<2>(best[k]);
      if (fragment[k] && target > 0) parent[findRoot(parent, k)] = findRoot(parent, slot[target]);
    }
    std::vector<int64_t> group_voxels(n, 0);
    std::vector<int> keeper(n, -1);  // per root: the member whose id the group keeps
    for (int k = 0; k < n; ++k) {
      const int r = findRoot(parent, k);
      group_voxels[r] += evidence[k].voxels;
      const int kk = keeper[r];
      const auto rank = [&](int i) { return std::make_pair(!fragment[i], evidence[i].voxels); };
      if (kk < 0 || rank(k) > rank(kk)) keeper[r] = k;
    }
    std::map<int32_t, int32_t> remap;  // instance id -> id it is reported under (0 = dropped)
    for (int k = 0; k < n; ++k) {
      const int r = findRoot(parent, k);
      const bool kept = areaOf(group_voxels[r], voxel_m) >= config.min_area_m2;
      remap[evidence[k].instance] = kept ? evidence[keeper[r]].instance : 0;
      if (!fragment[k]) continue;
      if (!kept) {
        ++out.dropped;
      } else if (keeper[r] != k) {
        ++out.folded;
      }
    }
    for (int32_t& id : out.instance) {
      if (id > 0) id = remap.at(id);
    }
  }
  for (const InstanceEvidence& e : instanceEvidence(graph, classes, out.instance)) {
    out.confidence[e.instance] = objectConfidence(e, voxel_m, config);
    out.evidence[e.instance] = objectEvidence(e, voxel_m);
  }
  return out;
}

}  // namespace internal
}  // namespace panmap
