#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "panmap/graph/internal/label_table.h"
#include "panmap/graph/optimiser.h"
#include "panmap/graph/superpoint_graph.h"

namespace panmap {
namespace internal {

/// Eq. 8, unary potential: psi_u(C) = -log(P_nu^C / sum_C' P_nu^C'), the sum over the label
/// space. The ratio is floored at `floor` (a class without score costs -log(floor), finite);
/// a vertex without any score (`score_sum` = 0) costs 0 for every class (uniform).
inline double unaryPotential(double score, double score_sum, double floor) {
  if (score_sum <= 0.0) return 0.0;
  return -std::log(std::max(score / score_sum, floor));
}

/// sum_C P_eps^C(S1, S2) made scale-free: divided by the smaller of the two vertices' score
/// sums (kSmaller), the most co-observation the weaker super-point could have had (Eq. 6 adds
/// at most P_o min(N1, N2) where Eq. 5 adds P_o N to each), or by their geometric mean
/// (kGeometric), which is 1 only when the two were always observed together. Raw sums grow with
/// frames and voxels like the scores do; leaving them raw while normalising the scores made every
/// disagreement cost about K_C, enough to relabel a fridge as the cabinet it touches through a few
/// boundary voxels. 0 when either vertex has no score (the edge then costs nothing).
inline double normalisedConfidence(double confidence_sum, double score_sum_a, double score_sum_b,
                                   OptimiserConfig::LinkScale link_scale) {
  const double scale = link_scale == OptimiserConfig::LinkScale::kGeometric
                           ? std::sqrt(score_sum_a * score_sum_b)
                           : std::min(score_sum_a, score_sum_b);
  return scale > 0.0 ? confidence_sum / scale : 0.0;
}

/// A vertex's score sum per voxel it holds (at least one): confidence-weighted observations
/// per voxel.
inline double observationsPerVoxel(const GraphVertex& vertex, double score_sum) {
  return score_sum / std::max<double>(1.0, vertex.num_voxels);
}

/// The share of a link trusted when its less observed end has n observations per voxel:
/// n / (n + half), 1 when half is 0 (OptimiserConfig::link_half_observations).
inline double linkTrust(double n, double half) {
  if (half <= 0.0) return 1.0;
  return n > 0.0 ? n / (n + half) : 0.0;
}

/// Whether the vertex is left unlabelled (OptimiserConfig::max_void_share): class 0 and no
/// instance, and its edges carry no pairwise term.
inline bool leftUnlabelled(const GraphVertex& vertex, const OptimiserConfig& config) {
  return vertex.void_share > config.max_void_share;  // never above 1: 1 turns it off
}

/// The edge factor of Eq. 9, 1 / (2 theta^2 c) with c the normalised confidence
/// (normalisedConfidence); 0 for an edge without confidence, which then costs nothing.
inline double edgeFactor(double confidence_sum, double theta) {
  return confidence_sum > 0.0 ? 1.0 / (2.0 * theta * theta * confidence_sum) : 0.0;
}

/// Eq. 9, pairwise potential: psi_p(C1, C2) = [C1 != C2] K_C exp(-k / (2 theta^2)) with
/// k = P_nu^C1(S1) P_nu^C2(S2) / sum_C P_eps^C(S1, S2). `p1`, `p2` are the NORMALISED scores
/// P_nu^C1(S1) / sum_C P_nu^C(S1) (0 for a vertex without scores): raw scores grow with the
/// number of frames and voxels, so k on raw scores would grow without bound and the cost
/// exp(-k / 2 theta^2) would vanish on any well-observed map. The denominator is normalised
/// the same way (normalisedConfidence): a weak link makes k large and disagreement cheap, a
/// strong link between uncertain super-points makes it cost up to K_C. `edge_factor` is
/// edgeFactor(normalised confidence, theta); 0 drops the edge.
inline double pairwisePotential(int32_t c1, int32_t c2, double p1, double p2, double edge_factor,
                                double K_C) {
  if (c1 == c2 || edge_factor <= 0.0) return 0.0;
  const double product = p1 * p2;
  if (product <= 0.0) return K_C;  // k = 0 (also avoids 0 * inf for tiny confidence sums)
  return K_C * std::exp(-product * edge_factor);
}

/// The semantic labelling problem in dense form. Label indices 0..L-1 name `labels`.
struct LabelProblem {
  /// Classes the optimiser considers, ascending: the classes of graph.classes with a positive
  /// score at some vertex, plus the initial (argmax) labels. Any other class of graph.classes
  /// has the floor unary and the largest pairwise cost K_C at every vertex, so it can never
  /// lower E and is left out.
  std::vector<int32_t> labels;
  int num_vertices = 0;
  LabelTable unary;                ///< Eq. 8 times the vertex weight, (vertex, label)
  LabelTable score;                ///< normalised P_nu, (vertex, label) (0 if no scores)
  std::vector<int> adj_offset;     ///< CSR over edges with a positive confidence sum, n + 1
  std::vector<int> adj_vertex;     ///< neighbour vertex index
  std::vector<double> adj_factor;  ///< edgeFactor of that edge
  std::vector<double> adj_kc;      ///< K_C times the weight of that edge
  std::vector<int> edge_a;         ///< the same edges once, vertex indices
  std::vector<int> edge_b;
  std::vector<double> edge_factor;
  std::vector<double> edge_kc;
  std::vector<int> initial;  ///< argmax labelling (label indices), see buildLabelProblem
  /// Number of labels L.
  int numLabels() const { return static_cast<int>(labels.size()); }
};

/// The weight of a vertex's unary under `weighting`: 1 (kNone) or its voxels, at least 1
/// (kSurface, kShared). An edge weighs the smaller of its two vertices' weights (kNone,
/// kSurface) or of their confidence-proportional shares of them (kShared).
double vertexWeight(const GraphVertex& vertex, OptimiserConfig::Weighting weighting);

/// Builds the problem from a checked graph. The initial label of a vertex is the argmax of its
/// scores over graph.classes (ties: the smaller class id); a vertex without scores keeps its
/// initial `semantic` if that is in graph.classes, else the smallest class.
LabelProblem buildLabelProblem(const SuperpointGraph& graph, const OptimiserConfig& config);

/// Eq. 7, the energy E(C) = sum_vertices psi_u + sum_edges psi_p of a labelling (label
/// indices per vertex).
double labellingEnergy(const LabelProblem& problem, const std::vector<int>& labels);

}  // namespace internal
}  // namespace panmap
