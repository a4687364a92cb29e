// The semantic energy of III-C: unary (Eq. 8) and pairwise (Eq. 9) potentials summed into
// E(C) (Eq. 7), in a dense per-vertex form for the alpha-beta swap and directly on the graph
// for semanticEnergy().
#include "panmap/graph/internal/semantic_energy.h"

#include <algorithm>
#include <string>

#include "panmap/core/error.h"
#include "panmap/graph/internal/graph_check.h"

namespace panmap {
namespace internal {
namespace {

/// Sum of the values whose class is in `classes` (classes outside the label space ignored).
double sumOver(const ClassValues& values, const ClassSet& classes) {
  double sum = 0.0;
  for (const auto& [c, v] : values) {
    if (classes.contains(c)) sum += v;
  }
  return sum;
}

/// Eq. 9's sum_C P_eps^C of an edge, discounted by how often the two super-points were seen
/// under two different masks instead (P_apart; off with discount_apart = false): a chair and
/// the floor it stands on share the chair's mask wherever its outline bleeds onto the floor,
/// but are apart in nearly every frame that shows both.
double edgeEvidence(const GraphEdge& e, const ClassSet& classes, const OptimiserConfig& config) {
  const double same = sumOver(e.confidences, classes);
  if (!config.discount_apart || !(same > 0.0)) return same;
  return same * same / (same + e.apart);
}

/// The value of class c, 0 when absent or outside `classes`.
double valueOf(const ClassValues& values, const ClassSet& classes, int32_t c) {
  if (!classes.contains(c)) return 0.0;
  const auto it = values.find(c);
  return it == values.end() ? 0.0 : it->second;
}

/// Per graph edge: the normalised confidence sum_C P_eps^C of Eq. 9 (0: the edge costs
/// nothing and is left out) and the weight its pairwise term counts with.
struct EdgeTerms {
  std::vector<double> confidence;
  std::vector<double> weight;
};

EdgeTerms edgeTerms(const SuperpointGraph& graph, const ClassSet& classes, const VertexIndex& index,
                    const OptimiserConfig& config, const std::vector<double>& score_sum,
                    const std::vector<double>& weight) {
  const size_t m = graph.edges.size();
  EdgeTerms terms{std::vector<double>(m, 0.0), std::vector<double>(m, 0.0)};
  std::vector<double> total(weight.size(), 0.0);  // per vertex: confidence of its edges
  for (size_t k = 0; k < m; ++k) {
    const GraphEdge& e = graph.edges[k];
    const int a = index(e.a);
    const int b = index(e.b);
    // An unlabelled vertex's class is not the swap's to choose: it neither pulls nor is pulled.
    if (leftUnlabelled(graph.vertices[a], config) || leftUnlabelled(graph.vertices[b], config)) {
      continue;
    }
    const double c = normalisedConfidence(edgeEvidence(e, classes, config), score_sum[a],
                                          score_sum[b], config.link_scale) *
                     linkTrust(std::min(observationsPerVoxel(graph.vertices[a], score_sum[a]),
                                        observationsPerVoxel(graph.vertices[b], score_sum[b])),
                               config.link_half_observations);
    if (!(c > 0.0)) continue;
    terms.confidence[k] = c;
    total[a] += c;
    total[b] += c;
  }
  for (size_t k = 0; k < m; ++k) {
    const double c = terms.confidence[k];
    if (c <= 0.0) continue;
    const int a = index(graph.edges[k].a);
    const int b = index(graph.edges[k].b);
    terms.weight[k] = config.weighting == OptimiserConfig::Weighting::kShared
                          ? std::min(weight[a] * c / total[a], weight[b] * c / total[b])
                          : std::min(weight[a], weight[b]);
  }
  return terms;
}

}  // namespace

double vertexWeight(const GraphVertex& vertex, OptimiserConfig::Weighting weighting) {
  if (weighting == OptimiserConfig::Weighting::kNone) return 1.0;
  return std::max<double>(1.0, vertex.num_voxels);
}

LabelProblem buildLabelProblem(const SuperpointGraph& graph, const OptimiserConfig& config) {
  const ClassSet classes(graph.classes);
  const VertexIndex index(graph);
  const int n = static_cast<int>(graph.vertices.size());
  LabelProblem problem;
  problem.num_vertices = n;
  std::vector<double> weight(n);
  for (int i = 0; i < n; ++i) weight[i] = vertexWeight(graph.vertices[i], config.weighting);

  // Initial classes (argmax) and the label space.
  std::vector<double> score_sum(n, 0.0);
  std::vector<int32_t> initial_class(n, 0);
  std::vector<int32_t> labels;
  for (int i = 0; i < n; ++i) {
    const GraphVertex& v = graph.vertices[i];
    double best = 0.0;
    int32_t best_class = 0;
    bool any = false;
    for (const auto& [c, s] : v.scores) {
      if (s <= 0.0 || !classes.contains(c)) continue;
      score_sum[i] += s;
      labels.push_back(c);
      if (!any || s > best) {  // map order: ties keep the smaller class
        best = s;
        best_class = c;
        any = true;
      }
    }
    initial_class[i] =
        any ? best_class : (classes.contains(v.semantic) ? v.semantic : classes.sorted().front());
    labels.push_back(initial_class[i]);
  }
  std::sort(labels.begin(), labels.end());
  labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
  problem.labels = labels;
  const ClassSet label_set(labels);
  const int L = static_cast<int>(labels.size());

  // Dense unary (Eq. 8) and normalised scores.
  problem.unary.assign(n, L, 0.0);
  problem.score.assign(n, L, 0.0);
  problem.initial.resize(n);
  const auto labelIndex = [&](int32_t c) {
    return static_cast<int>(std::lower_bound(labels.begin(), labels.end(), c) - labels.begin());
  };
  std::vector<double> unscored(n);  // the unary of a label without a score
  for (int i = 0; i < n; ++i) {
    unscored[i] = weight[i] * unaryPotential(0.0, score_sum[i], config.score_floor);
  }
  for (int l = 0; l < L; ++l) {
    std::copy(unscored.begin(), unscored.end(), problem.unary.row(l));
  }
  for (int i = 0; i < n; ++i) {
    problem.initial[i] = labelIndex(initial_class[i]);
    for (const auto& [c, s] : graph.vertices[i].scores) {
      if (s <= 0.0 || !label_set.contains(c)) continue;
      const int l = labelIndex(c);
      problem.unary(i, l) = weight[i] * unaryPotential(s, score_sum[i], config.score_floor);
      problem.score(i, l) = s / score_sum[i];
    }
  }

  // Edges with a positive confidence sum, once and as CSR adjacency.
  const EdgeTerms terms = edgeTerms(graph, classes, index, config, score_sum, weight);
  std::vector<int> degree(n + 1, 0);
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const double factor = edgeFactor(terms.confidence[k], config.theta);
    if (factor <= 0.0) continue;
    const int a = index(graph.edges[k].a);
    const int b = index(graph.edges[k].b);
    problem.edge_a.push_back(a);
    problem.edge_b.push_back(b);
    problem.edge_factor.push_back(factor);
    problem.edge_kc.push_back(config.K_C * terms.weight[k]);
    ++degree[a + 1];
    ++degree[b + 1];
  }
  for (int i = 0; i < n; ++i) degree[i + 1] += degree[i];
  problem.adj_offset = degree;
  problem.adj_vertex.resize(degree[n]);
  problem.adj_factor.resize(degree[n]);
  problem.adj_kc.resize(degree[n]);
  std::vector<int> fill(degree.begin(), degree.end() - 1);
  for (size_t k = 0; k < problem.edge_a.size(); ++k) {
    for (const auto& [from, to] : {std::make_pair(problem.edge_a[k], problem.edge_b[k]),
                                   std::make_pair(problem.edge_b[k], problem.edge_a[k])}) {
      problem.adj_vertex[fill[from]] = to;
      problem.adj_factor[fill[from]] = problem.edge_factor[k];
      problem.adj_kc[fill[from]++] = problem.edge_kc[k];
    }
  }
  return problem;
}

double labellingEnergy(const LabelProblem& problem, const std::vector<int>& labels) {
  double energy = 0.0;
  for (int i = 0; i < problem.num_vertices; ++i) energy += problem.unary(i, labels[i]);
  for (size_t k = 0; k < problem.edge_a.size(); ++k) {
    const int a = problem.edge_a[k];
    const int b = problem.edge_b[k];
    energy +=
        pairwisePotential(labels[a], labels[b], problem.score(a, labels[a]),
                          problem.score(b, labels[b]), problem.edge_factor[k], problem.edge_kc[k]);
  }
  return energy;
}

}  // namespace internal

double semanticEnergy(const SuperpointGraph& graph, const std::map<int32_t, int32_t>& labels,
                      const OptimiserConfig& config) {
  config.check();
  internal::checkGraph(graph);
  const internal::ClassSet classes(graph.classes);
  const internal::VertexIndex index(graph);
  const size_t n = graph.vertices.size();
  std::vector<int32_t> label(n);
  std::vector<double> normalised(n, 0.0), sums(n, 0.0), weight(n, 1.0);
  double energy = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const GraphVertex& v = graph.vertices[i];
    const auto it = labels.find(v.id);
    if (it == labels.end()) {
      throw Error("labels: no class for super-point " + std::to_string(v.id));
    }
    label[i] = it->second;
    const double sum = internal::sumOver(v.scores, classes);
    sums[i] = sum;
    const double score = internal::valueOf(v.scores, classes, label[i]);
    normalised[i] = sum > 0.0 ? score / sum : 0.0;
    weight[i] = internal::vertexWeight(v, config.weighting);
    // An unlabelled vertex's class is fixed (class 0): its unary is no part of the choice.
    if (!internal::leftUnlabelled(v, config)) {
      energy += weight[i] * internal::unaryPotential(score, sum, config.score_floor);
    }
  }
  const internal::EdgeTerms terms =
      internal::edgeTerms(graph, classes, index, config, sums, weight);
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const int a = index(graph.edges[k].a);
    const int b = index(graph.edges[k].b);
    const double factor = internal::edgeFactor(terms.confidence[k], config.theta);
    energy += internal::pairwisePotential(label[a], label[b], normalised[a], normalised[b], factor,
                                          config.K_C * terms.weight[k]);
  }
  return energy;
}

}  // namespace panmap
