#include "panmap/graph/internal/class_consensus.h"

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
  // The one-mask and two-mask evidence of the edge between a and b, when both are things.
  const auto linkOf = [&](const GraphEdge& e, int a, int b, LinkEvidence* link) {
    if (!isThing(classes[a]) || !isThing(classes[b])) return false;
    for (const auto& [c, v] : e.confidences) {
      if (isThing(c)) link->same += v;
    }
    link->apart = e.apart;
    return link->same > 0.0;
  };
  std::vector<LinkPair> pairs;
  pairs.reserve(graph.edges.size());
  for (const GraphEdge& e : graph.edges) {
    const int a = index(e.a), b = index(e.b);
    LinkEvidence link;
    if (linkOf(e, a, b, &link)) pairs.push_back({a, b, link});  // edges come sorted by (a, b)
  }
  const std::vector<int> root = clusterByAffinity(linksOf(n, pairs), std::move(observed),
                                                  config.join_affinity, config.min_coverage);
  // Groups of two or more classes, by root, in per-root arrays (no map or set per group).
  constexpr int32_t kNone = -1;
  std::vector<int32_t> first_class(n, kNone);
  std::vector<char> mixed(n, 0);
  for (int i = 0; i < n; ++i) {
    if (!isThing(classes[i])) continue;
    int32_t& first = first_class[root[i]];
    if (first == kNone) {
      first = classes[i];
    } else if (first != classes[i]) {
      mixed[root[i]] = 1;
    }
  }
  std::vector<ClassValues> group_score(n);  // root -> thing class -> summed score, mixed only
  for (int i = 0; i < n; ++i) {
    if (!isThing(classes[i]) || !mixed[root[i]]) continue;
    for (const auto& [c, s] : graph.vertices[i].scores) {
      if (isThing(c)) group_score[root[i]][c] += s;
    }
  }
  std::vector<int32_t> decided(n, 0);  // the class a mixed group decided (0: none)
  int groups = 0;
  for (int r = 0; r < n; ++r) {
    if (!mixed[r]) continue;
    ++groups;
    double best_score = -1.0;
    for (const auto& [c, s] : group_score[r]) {  // ascending class: ties keep the smaller
      if (s > best_score) decided[r] = c, best_score = s;
    }
  }
  // Members in doubt, each with the class its group decided.
  std::vector<std::pair<int, int32_t>> candidates;
  std::vector<char> in_doubt(n, 0);
  for (int i = 0; i < n; ++i) {
    if (!isThing(classes[i]) || !mixed[root[i]]) continue;
    const int32_t target = decided[root[i]];
    if (target == classes[i]) continue;
    // Only where its own views left it in doubt: a surface the network hardly ever called the
    // group's class (a box beside a shelf, joined through the shelf mask's outline) keeps its own.
    const auto own = graph.vertices[i].scores.find(classes[i]);
    const auto group = graph.vertices[i].scores.find(target);
    const double own_score = own == graph.vertices[i].scores.end() ? 0.0 : own->second;
    const double group_score = group == graph.vertices[i].scores.end() ? 0.0 : group->second;
    if (!(group_score >= config.consensus_min_ratio * own_score && group_score > 0.0)) continue;
    candidates.emplace_back(i, target);
    in_doubt[i] = 1;
  }
  // Their direct links, as the clustering started from them (it consumed its copy).
  std::vector<Links> direct(n);
  if (!candidates.empty()) {
    for (const GraphEdge& e : graph.edges) {
      const int a = index(e.a), b = index(e.b);
      if (!in_doubt[a] && !in_doubt[b]) continue;
      LinkEvidence link;
      if (!linkOf(e, a, b, &link)) continue;
      if (in_doubt[a]) direct[a].emplace_hint(direct[a].end(), b, link);
      if (in_doubt[b]) direct[b].emplace_hint(direct[b].end(), a, link);
    }
  }
  // And only where the network showed it in one mask with the members that hold that class
  // more often than in two, and more often than with the members that share its own class.
  // Average linkage also joins through scraps of a few voxels that touch both (books on a
  // shelf, joined through the shelf's slivers between them though views with both mostly split
  // them), and a member must not take a class along such a chain; nor leave the books it was
  // shown with far more often for a shelf whose mask outline it sat in now and then. Sweeps in
  // rounds, each against the classes of the round before (independent of order), so a class
  // passes from member to member only along direct evidence.
  std::vector<int32_t> out = classes;
  ClassConsensusStats counts;
  counts.groups = groups;
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
