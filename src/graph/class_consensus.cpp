#include "panmap/graph/internal/class_consensus.h"

#include <map>
#include <set>
#include <utility>

#include "panmap/graph/internal/affinity_clustering.h"
#include "panmap/graph/internal/graph_check.h"

namespace panmap {
namespace internal {

std::vector<int32_t> classConsensus(const SuperpointGraph& graph,
                                    const std::vector<int32_t>& classes,
                                    const OptimiserConfig& config, ClassConsensusStats* stats) {
  const int n = static_cast<int>(graph.vertices.size());
  const ClassSet no_instance = noInstanceClasses(graph);
  const ClassSet known(graph.classes);
  const auto isThing = [&](int32_t c) {
    return c > 0 && known.contains(c) && !no_instance.contains(c);
  };
  const VertexIndex index(graph);
  std::vector<double> observed(n, 0.0);
  for (int i = 0; i < n; ++i) {
    if (!isThing(classes[i])) continue;
    for (const auto& [c, s] : graph.vertices[i].scores) {
      if (isThing(c)) observed[i] += s;
    }
  }
  std::vector<Links> links(n);
  for (const GraphEdge& e : graph.edges) {
    const int a = index(e.a), b = index(e.b);
    if (!isThing(classes[a]) || !isThing(classes[b])) continue;
    LinkEvidence link;
    for (const auto& [c, v] : e.confidences) {
      if (isThing(c)) link.same += v;
    }
    link.apart = e.apart;
    if (!(link.same > 0.0)) continue;
    // Edges come sorted by (a, b): both lists grow at their ends.
    links[a].emplace_hint(links[a].end(), b, link);
    links[b].emplace_hint(links[b].end(), a, link);
  }
  const std::vector<Links> direct = links;
  const std::vector<int> root = clusterByAffinity(std::move(links), std::move(observed),
                                                  config.join_affinity, config.min_coverage);
  std::map<int, std::set<int32_t>> group_classes;        // root -> classes of its members
  std::map<int, std::map<int32_t, double>> group_score;  // root -> thing class -> score
  for (int i = 0; i < n; ++i) {
    if (!isThing(classes[i])) continue;
    group_classes[root[i]].insert(classes[i]);
    for (const auto& [c, s] : graph.vertices[i].scores) {
      if (isThing(c)) group_score[root[i]][c] += s;
    }
  }
  std::vector<int32_t> out = classes;
  std::map<int, int32_t> decided;
  for (const auto& [r, members] : group_classes) {
    if (members.size() < 2) continue;
    int32_t best = 0;
    double best_score = -1.0;
    for (const auto& [c, s] : group_score[r]) {  // ascending class: ties keep the smaller
      if (s > best_score) best = c, best_score = s;
    }
    decided[r] = best;
  }
  // Members in doubt, each with the class its group decided.
  std::vector<std::pair<int, int32_t>> candidates;
  for (int i = 0; i < n; ++i) {
    if (!isThing(classes[i])) continue;
    const auto it = decided.find(root[i]);
    if (it == decided.end() || it->second == classes[i]) continue;
    // Only where its own views left it in doubt: a surface the network hardly ever called the
    // group's class (a box beside a shelf, joined through the shelf mask's outline) keeps its own.
    const auto own = graph.vertices[i].scores.find(classes[i]);
    const auto group = graph.vertices[i].scores.find(it->second);
    const double own_score = own == graph.vertices[i].scores.end() ? 0.0 : own->second;
    const double group_score = group == graph.vertices[i].scores.end() ? 0.0 : group->second;
    if (!(group_score >= config.consensus_min_ratio * own_score && group_score > 0.0)) continue;
    candidates.emplace_back(i, it->second);
  }
  // And only where the network showed it in one mask with the members that hold that class
  // more often than in two, and more often than with the members that share its own class.
  // Average linkage also joins through scraps of a few voxels that touch both (books on a
  // shelf, joined through the shelf's slivers between them though views with both mostly split
  // them), and a member must not take a class along such a chain; nor leave the books it was
  // shown with far more often for a shelf whose mask outline it sat in now and then. Sweeps in
  // rounds, each against the classes of the round before (independent of order), so a class
  // passes from member to member only along direct evidence.
  ClassConsensusStats counts;
  counts.groups = static_cast<int>(decided.size());
  while (true) {
    std::vector<std::pair<int, int32_t>> taken;
    for (const auto& [i, target] : candidates) {
      if (out[i] == target) continue;
      LinkEvidence with_class;
      double with_own = 0.0;
      for (const auto& [j, link] : direct[i]) {
        if (root[j] != root[i]) continue;
        if (out[j] == out[i]) with_own += link.same;
        if (out[j] != target) continue;
        with_class.same += link.same;
        with_class.apart += link.apart;
      }
      if (with_class.same > with_class.apart && with_class.same > with_own) {
        taken.emplace_back(i, target);
      }
    }
    if (taken.empty()) break;
    for (const auto& [i, target] : taken) out[i] = target;
    counts.superpoints += static_cast<int>(taken.size());
  }
  if (stats) *stats = counts;
  return out;
}

}  // namespace internal
}  // namespace panmap
