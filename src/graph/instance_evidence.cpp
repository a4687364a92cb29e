#include "panmap/graph/instance_evidence.h"

#include <algorithm>
#include <map>

#include "panmap/core/error.h"
#include "panmap/graph/internal/graph_check.h"

namespace panmap {

std::vector<InstanceEvidence> instanceEvidence(const SuperpointGraph& graph,
                                               const std::vector<int32_t>& classes,
                                               const std::vector<int32_t>& instances) {
  const size_t n = graph.vertices.size();
  if (classes.size() != n || instances.size() != n) {
    throw Error("instanceEvidence: classes and instances must have one entry per vertex");
  }
  std::map<int32_t, InstanceEvidence> by_id;
  for (size_t i = 0; i < n; ++i) {
    if (instances[i] <= 0) continue;
    const GraphVertex& v = graph.vertices[i];
    InstanceEvidence& e = by_id[instances[i]];
    e.instance = instances[i];
    e.class_id = classes[i];
    ++e.superpoints;
    e.voxels += v.num_voxels;
    const auto s = v.scores.find(classes[i]);
    if (s != v.scores.end()) e.score += s->second;
    for (const auto& [cls, value] : v.scores) e.score_all += value;
  }
  const internal::VertexIndex index(graph);
  for (const GraphEdge& edge : graph.edges) {
    const int a = index(edge.a), b = index(edge.b);
    if (classes[a] != classes[b]) continue;
    const auto c = edge.confidences.find(classes[a]);
    if (c == edge.confidences.end()) continue;
    const int32_t ia = instances[a], ib = instances[b];
    if (ia > 0 && ia == ib) {
      by_id[ia].inner_link = std::max(by_id[ia].inner_link, c->second);
      continue;
    }
    if (ia > 0) by_id[ia].outer_link = std::max(by_id[ia].outer_link, c->second);
    if (ib > 0) by_id[ib].outer_link = std::max(by_id[ib].outer_link, c->second);
  }
  std::vector<InstanceEvidence> out;
  out.reserve(by_id.size());
  for (const auto& [id, e] : by_id) out.push_back(e);
  return out;
}

}  // namespace panmap
