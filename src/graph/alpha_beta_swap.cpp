// Alpha-beta swap (Boykov, Veksler, Zabih, "Fast approximate energy minimization via graph
// cuts", PAMI 2001) over the semantic energy of Eq. 7.
//
// One swap move for labels (alpha, beta) relabels the vertices P currently labelled alpha or
// beta, each to alpha or beta; everything else stays. With x_p = 0 for alpha and 1 for beta, the
// binary energy of the move is
//   sum_p D_p(x_p) + sum_{(p,q) in P} V_pq(x_p, x_q),
//   D_p(l) = psi_u(p, l) + sum_{q not in P} psi_p(l, l_q)        (neighbours outside P fixed),
//   V_pq(alpha, alpha) = V_pq(beta, beta) = 0,
//   V_pq(alpha, beta) = psi_p(alpha, beta) on (p, q), V_pq(beta, alpha) = psi_p(beta, alpha).
// Eq. 9 is not symmetric in the labels for a given edge (k uses P_nu^alpha(p) P_nu^beta(q) one
// way and P_nu^beta(p) P_nu^alpha(q) the other), so it is not a semi-metric in the strict sense
// of BVZ (V(a, b) = V(b, a) for every edge). It does not need to be: psi_p >= 0 and
// psi_p(a, a) = 0, so the binary energy of every move is submodular
// (V(a,a) + V(b,b) = 0 <= V(a,b) + V(b,a)) and one minimum cut (BinaryCut) solves it exactly
// with the two directed weights. Every move is the exact best swap, E never increases, and the
// result is a local minimum with respect to swap moves.
//
// Speed-ups, all exact:
//  - pair_sum_[p][l] = sum over all neighbours q of psi_p(l, l_q) is kept up to date as labels
//    change, so D_p needs only the neighbours inside the move, not an exp per outside neighbour;
//  - a move is solved only over the vertices of P that can change (see selectVertices);
//  - a move is skipped when nothing it depends on changed since it was last solved (stale());
//  - a move computes the switch cost only of vertices that a lower bound does not rule out
//    (see mayMove()): on a building's graph the moves of three sweeps had computed 1.2 million
//    of them for 2,859 that switched, over half of the swap's time.
#include "panmap/graph/internal/alpha_beta_swap.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "panmap/graph/internal/binary_cut.h"

namespace panmap {
namespace internal {
namespace {

/// A pair term of the move between local vertices i < j.
struct PairLink {
  int i;
  int j;
  double ab;  ///< V(x_i = alpha, x_j = beta)
  double ba;  ///< V(x_i = beta, x_j = alpha)
};

/// Swap moves over one labelling, with buffers reused across moves.
class SwapSolver {
 public:
  SwapSolver(const LabelProblem& problem, std::vector<int>& labels, SwapSeeds seeds)
      : problem_(problem), labels_(labels), L_(problem.numLabels()), seeds_(seeds) {
    const int n = problem.num_vertices;
    local_.assign(n, -1);
    switch_cost_.assign(n, 0.0);
    gain_.assign(n, 0.0);
    costed_at_.assign(n, -1);
    members_.resize(L_);
    changed_at_.assign(L_, 0);
    evaluated_at_.assign(static_cast<size_t>(L_) * L_, -1);
    kc_with_.assign(n, L_, 0.0);
    std::vector<double> kc_total(n, 0.0);
    scored_offset_.assign(n + 1, 0);
    for (int p = 0; p < n; ++p) {
      members_[labels[p]].push_back(p);
      for (int e = problem.adj_offset[p]; e < problem.adj_offset[p + 1]; ++e) {
        kc_with_(p, labels[problem.adj_vertex[e]]) += problem.adj_kc[e];
        kc_total[p] += problem.adj_kc[e];
      }
    }
    // Labels with a score per vertex, ascending, as CSR; read label by label (the arrays are
    // label-major).
    for (int l = 0; l < L_; ++l) {
      const double* score = problem.score.row(l);
      for (int p = 0; p < n; ++p) scored_offset_[p + 1] += score[p] > 0.0;
    }
    for (int p = 0; p < n; ++p) scored_offset_[p + 1] += scored_offset_[p];
    scored_label_.resize(scored_offset_[n]);
    std::vector<int> fill(scored_offset_.begin(), scored_offset_.end() - 1);
    for (int l = 0; l < L_; ++l) {
      const double* score = problem.score.row(l);
      for (int p = 0; p < n; ++p) {
        if (score[p] > 0.0) scored_label_[fill[p]++] = l;
      }
    }
    // pair_sum_: the edge's K per neighbour with another label, unless p has a score for l
    // (exp terms).
    pair_sum_.assign(n, L_, 0.0);
    for (int l = 0; l < L_; ++l) {
      double* pair_sum = pair_sum_.row(l);
      const double* kc_with = kc_with_.row(l);
      for (int p = 0; p < n; ++p) pair_sum[p] = kc_total[p] - kc_with[p];
    }
    for (int p = 0; p < n; ++p) {
      for (int s = scored_offset_[p]; s < scored_offset_[p + 1]; ++s) {
        const int l = scored_label_[s];
        double sum = 0.0;
        for (int e = problem.adj_offset[p]; e < problem.adj_offset[p + 1]; ++e) {
          sum += pairTo(p, l, problem.adj_vertex[e], labels[problem.adj_vertex[e]], e);
        }
        pair_sum_(p, l) = sum;
      }
    }
    kc_total_ = std::move(kc_total);
    // The two smallest unaries of each vertex, and the label of the smallest.
    lowest_unary_.assign(n, INFINITY);
    second_unary_.assign(n, INFINITY);
    lowest_label_.assign(n, -1);
    for (int l = 0; l < L_; ++l) {
      const double* unary = problem.unary.row(l);
      for (int p = 0; p < n; ++p) {
        if (unary[p] < lowest_unary_[p]) {
          second_unary_[p] = lowest_unary_[p];
          lowest_unary_[p] = unary[p];
          lowest_label_[p] = l;
        } else if (unary[p] < second_unary_[p]) {
          second_unary_[p] = unary[p];
        }
      }
    }
    may_move_.resize(n);
    for (int p = 0; p < n; ++p) may_move_[p] = mayMove(p);
  }

  /// Vertices whose switch cost the moves computed.
  long long costed() const { return costed_; }
  /// Seeds the bound would have left out (counted with SwapSeeds::kEveryVertex).
  long long boundMisses() const { return bound_misses_; }

  /// False when the move (alpha, beta) cannot have changed since it was last solved: no vertex
  /// labelled alpha or beta, nor any neighbour of one, changed label since. (An accepted move
  /// leaves the pair optimal for itself.)
  bool stale(int alpha, int beta) const {
    const int64_t when = evaluated_at_[pairAt(alpha, beta)];
    return when < 0 || changed_at_[alpha] > when || changed_at_[beta] > when;
  }

  /// The best swap move of (alpha, beta); applies it when it lowers E. Returns true then.
  bool move(int alpha, int beta) {
    ++clock_;
    selectVertices(alpha, beta);
    const int m = static_cast<int>(verts_.size());
    bool better = false;
    if (m > 0) {
      for (int k = 0; k < m; ++k) local_[verts_[k]] = k;
      buildTerms(alpha, beta);
      current_.resize(m);
      for (int k = 0; k < m; ++k) current_[k] = labels_[verts_[k]] == beta;
      if (links_.empty()) {
        cut_.resize(m);
        for (int k = 0; k < m; ++k) {  // independent vertices; ties keep the current label
          cut_[k] = cost_b_[k] < cost_a_[k] || (cost_b_[k] == cost_a_[k] && current_[k]);
        }
      } else {
        cut_solver_.reset(m);
        for (int k = 0; k < m; ++k) cut_solver_.addUnary(k, cost_a_[k], cost_b_[k]);
        for (const PairLink& link : links_) cut_solver_.addPair(link.i, link.j, link.ab, link.ba);
        cut_solver_.solve(cut_);
      }
      const double before = moveEnergy(current_);
      const double after = moveEnergy(cut_);
      better = after < before - 1e-12 * (1.0 + std::abs(before));
      for (int v : verts_) local_[v] = -1;
    }
    if (better) apply(alpha, beta);
    evaluated_at_[pairAt(alpha, beta)] = clock_;
    return better;
  }

 private:
  /// Index of the label pair (alpha, beta) in evaluated_at_.
  size_t pairAt(int alpha, int beta) const { return static_cast<size_t>(alpha) * L_ + beta; }

  /// psi_p(l, lq) of the edge at adjacency entry e from p to q (Eq. 9).
  double pairTo(int p, int l, int q, int lq, int e) const {
    return pairwisePotential(l, lq, problem_.score(p, l), problem_.score(q, lq),
                             problem_.adj_factor[e], problem_.adj_kc[e]);
  }

  /// verts_: the vertices of the move that may change, ascending; the other vertices of P keep
  /// their labels, which leaves the move exact. For p labelled own in {alpha, beta}, `other`
  /// the other label of the pair, let
  ///   c_p = [psi_u(other) + sum_q psi_p(other, l_q) over the neighbours not labelled own]
  ///         - [psi_u(own) + sum_q psi_p(own, l_q) over all neighbours],
  /// the change of E when p alone switches, less the terms psi_p(other, own) >= 0 of its
  /// neighbours labelled own. Any set R of vertices that switch in a move raises E by at least
  /// sum_{p in R} (c_p - sum of V_pq(own, other) over the neighbours q of p labelled own that
  /// switch too and are not in R) (a pair of R with opposite labels, or a neighbour labelled
  /// other, can give back at most V_pq(own, other), which c_p already counts). So starting
  /// from {p : c_p < 0} and adding a vertex when the links V_pq(own, other) to same-labelled
  /// vertices already added exceed c_p, the vertices left out can be dropped from any optimal
  /// move without raising E: an optimal move over the set is an optimal move.
  void selectVertices(int alpha, int beta) {
    ++select_clock_;
    verts_.clear();
    for (const auto& [own, other] : {std::make_pair(alpha, beta), std::make_pair(beta, alpha)}) {
      for (int v : members_[own]) {
        if (seeds_ == SwapSeeds::kBounded && !may_move_[v]) continue;
        costSwitch(v, own, other);
        if (switch_cost_[v] < 0.0 && !may_move_[v]) ++bound_misses_;  // kEveryVertex only
        if (switch_cost_[v] < 0.0) {
          local_[v] = 0;
          verts_.push_back(v);
        }
      }
    }
    for (size_t k = 0; k < verts_.size(); ++k) {
      const int v = verts_[k];
      const int lv = labels_[v];
      const int other = lv == alpha ? beta : alpha;
      for (int e = problem_.adj_offset[v]; e < problem_.adj_offset[v + 1]; ++e) {
        const int q = problem_.adj_vertex[e];
        if (local_[q] >= 0 || labels_[q] != lv) continue;
        if (costed_at_[q] != select_clock_) costSwitch(q, lv, other);
        gain_[q] += pairwisePotential(lv, other, problem_.score(q, lv), problem_.score(v, other),
                                      problem_.adj_factor[e], problem_.adj_kc[e]);
        if (gain_[q] > switch_cost_[q]) {
          local_[q] = 0;
          verts_.push_back(q);
        }
      }
    }
    for (int v : verts_) local_[v] = -1;
    std::sort(verts_.begin(), verts_.end());
  }

  /// switch_cost_[v] = c_p of v labelled own for the move to `other` (selectVertices), and
  /// gain_[v] = 0, for this move.
  void costSwitch(int v, int own, int other) {
    const double stay = problem_.unary(v, own) + pair_sum_(v, own);
    double swap = problem_.unary(v, other) + pair_sum_(v, other);
    if (problem_.score(v, other) > 0.0) {
      for (int e = problem_.adj_offset[v]; e < problem_.adj_offset[v + 1]; ++e) {
        const int q = problem_.adj_vertex[e];
        if (labels_[q] == own) swap -= pairTo(v, other, q, own, e);
      }
    } else {  // psi_p(other, own) = the edge's K without a score for `other`
      swap -= kc_with_(v, own);
    }
    switch_cost_[v] = swap - stay;
    gain_[v] = 0.0;
    costed_at_[v] = select_clock_;
    ++costed_;
  }

  /// False when no move can make p a seed (switch cost < 0): its swap term is its unary for
  /// the other label plus pair terms to neighbours not labelled as p is, each >= 0, so the
  /// cost is at least the smallest unary of a label other than p's, less its stay term. The
  /// margin covers the rounding of the sums (pair_sum_ is kept up to date by increments), so a
  /// vertex is only ever skipped when the full computation would also find cost >= 0.
  bool mayMove(int p) const {
    const int own = labels_[p];
    const double least_other = own == lowest_label_[p] ? second_unary_[p] : lowest_unary_[p];
    const double stay = problem_.unary(p, own) + pair_sum_(p, own);
    const double margin =
        1e-9 * (1.0 + std::abs(least_other) + std::abs(stay) + std::abs(kc_total_[p]));
    return !(least_other - stay >= margin);
  }

  /// D_p(alpha), D_p(beta) of every vertex of the move and the pair terms between them:
  /// pair_sum_ minus the terms of the neighbours inside the move.
  void buildTerms(int alpha, int beta) {
    const int m = static_cast<int>(verts_.size());
    cost_a_.resize(m);
    cost_b_.resize(m);
    const double* unary_a = problem_.unary.row(alpha);
    const double* unary_b = problem_.unary.row(beta);
    const double* pair_a = pair_sum_.row(alpha);
    const double* pair_b = pair_sum_.row(beta);
    for (int k = 0; k < m; ++k) {
      const int p = verts_[k];
      cost_a_[k] = unary_a[p] + pair_a[p];
      cost_b_[k] = unary_b[p] + pair_b[p];
    }
    links_.clear();
    for (int k = 0; k < m; ++k) {
      const int p = verts_[k];
      const int lp = labels_[p];
      for (int e = problem_.adj_offset[p]; e < problem_.adj_offset[p + 1]; ++e) {
        const int q = problem_.adj_vertex[e];
        const int kq = local_[q];
        if (kq <= k) continue;  // outside the move (in pair_sum_), or seen from q
        const int lq = labels_[q];
        const double ab = pairTo(p, alpha, q, beta, e);  // V_pq(alpha, beta) = V_qp(beta, alpha)
        const double ba = pairTo(p, beta, q, alpha, e);  // V_pq(beta, alpha) = V_qp(alpha, beta)
        if (lq == beta) cost_a_[k] -= ab;
        if (lq == alpha) cost_b_[k] -= ba;
        if (lp == beta) cost_a_[kq] -= ba;
        if (lp == alpha) cost_b_[kq] -= ab;
        if (ab > 0.0 || ba > 0.0) links_.push_back({k, kq, ab, ba});
      }
    }
  }

  /// The binary energy of the move for x (1: beta), up to the constant of the rest of E.
  double moveEnergy(const std::vector<char>& x) const {
    double energy = 0.0;
    for (size_t k = 0; k < x.size(); ++k) energy += x[k] ? cost_b_[k] : cost_a_[k];
    for (const PairLink& link : links_) {
      if (x[link.i] != x[link.j]) energy += x[link.i] ? link.ba : link.ab;
    }
    return energy;
  }

  /// Applies cut_ to the labels, the label lists, the neighbour label counts and pair_sum_.
  void apply(int alpha, int beta) {
    ++clock_;
    changed_at_[alpha] = changed_at_[beta] = clock_;
    for (size_t k = 0; k < verts_.size(); ++k) {
      const int v = verts_[k];
      const int label = cut_[k] ? beta : alpha;
      const int old = labels_[v];
      if (old == label) continue;
      labels_[v] = label;
      for (int e = problem_.adj_offset[v]; e < problem_.adj_offset[v + 1]; ++e) {
        const int q = problem_.adj_vertex[e];
        kc_with_(q, old) -= problem_.adj_kc[e];
        kc_with_(q, label) += problem_.adj_kc[e];
        changed_at_[labels_[q]] = clock_;
        // pair_sum_[q][l] += psi(l, label) - psi(l, old): exp terms where q has a score for l,
        // else K [l != label] - K [l != old] with the edge's K.
        for (int s = scored_offset_[q]; s < scored_offset_[q + 1]; ++s) {
          const int l = scored_label_[s];
          pair_sum_(q, l) += pairTo(q, l, v, label, e) - pairTo(q, l, v, old, e);
        }
        if (problem_.score(q, old) <= 0.0) pair_sum_(q, old) += problem_.adj_kc[e];
        if (problem_.score(q, label) <= 0.0) pair_sum_(q, label) -= problem_.adj_kc[e];
        may_move_[q] = mayMove(q);  // its pair sums changed
      }
      may_move_[v] = mayMove(v);  // its label changed
    }
    merged_.clear();
    std::merge(members_[alpha].begin(), members_[alpha].end(), members_[beta].begin(),
               members_[beta].end(), std::back_inserter(merged_));
    members_[alpha].clear();
    members_[beta].clear();
    for (int v : merged_) members_[labels_[v]].push_back(v);
  }

  const LabelProblem& problem_;
  std::vector<int>& labels_;
  const int L_;
  const SwapSeeds seeds_;
  std::vector<std::vector<int>> members_;  ///< vertices per label, ascending
  LabelTable kc_with_;                     ///< (vertex, label): sum of the K of edges to that label
  LabelTable pair_sum_;                    ///< (vertex, label): sum_q psi_p(label, l_q)
  std::vector<int> scored_offset_;         ///< CSR of the labels each vertex has a score for
  std::vector<int> scored_label_;
  int64_t clock_ = 0;                  ///< counts solved and accepted moves
  std::vector<int64_t> changed_at_;    ///< per label: clock of the last change it depends on
  std::vector<int64_t> evaluated_at_;  ///< per label pair: clock when last solved
  std::vector<double> kc_total_;       ///< per vertex: the K of all its edges
  std::vector<double> lowest_unary_;   ///< per vertex: its smallest unary
  std::vector<double> second_unary_;   ///< per vertex: its second smallest unary
  std::vector<int> lowest_label_;      ///< per vertex: the label of the smallest
  std::vector<char> may_move_;         ///< per vertex: mayMove(), kept up to date
  int64_t select_clock_ = 0;           ///< counts selectVertices calls
  long long costed_ = 0;               ///< switch costs computed
  long long bound_misses_ = 0;         ///< seeds with mayMove() false
  // Per-move buffers.
  std::vector<int> local_;           ///< vertex -> index in the move, -1 outside
  std::vector<double> switch_cost_;  ///< selectVertices: c_p of the non-seeds
  std::vector<double> gain_;         ///< selectVertices: links to vertices that joined
  std::vector<int64_t> costed_at_;   ///< selectVertices: select_clock_ when switch_cost_ was set
  std::vector<int> verts_;
  std::vector<int> merged_;
  std::vector<double> cost_a_;
  std::vector<double> cost_b_;
  std::vector<PairLink> links_;
  std::vector<char> current_;
  std::vector<char> cut_;
  BinaryCut cut_solver_;
};

}  // namespace

SwapStats alphaBetaSwap(const LabelProblem& problem, std::vector<int>& labels, int max_sweeps,
                        SwapSeeds seeds) {
  SwapStats stats;
  const int L = problem.numLabels();
  if (L < 2 || problem.num_vertices == 0) return stats;
  SwapSolver solver(problem, labels, seeds);
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    ++stats.sweeps;
    bool improved = false;
    for (int alpha = 0; alpha < L; ++alpha) {
      for (int beta = alpha + 1; beta < L; ++beta) {
        if (!solver.stale(alpha, beta)) continue;
        ++stats.solved;
        if (solver.move(alpha, beta)) {
          improved = true;
          ++stats.moves;
        }
      }
    }
    if (!improved) break;
  }
  stats.costed = solver.costed();
  stats.bound_misses = solver.boundMisses();
  return stats;
}

}  // namespace internal
}  // namespace panmap
