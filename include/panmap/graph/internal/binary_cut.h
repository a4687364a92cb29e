#pragma once

#include <utility>
#include <vector>

#include <boost/graph/compressed_sparse_row_graph.hpp>

namespace panmap {
namespace internal {

/// Exact minimiser of a submodular binary energy
///   E(x) = sum_k D_k(x_k) + sum_(i,j) ([x_i = 0, x_j = 1] c01 + [x_i = 1, x_j = 0] c10),
/// D, c01, c10 >= 0, by one s-t minimum cut (Boost Graph's boykov_kolmogorov_max_flow on a
/// compressed sparse row graph). Buffers are reused across solves.
class BinaryCut {
 public:
  /// Starts a problem of `num_variables` variables without terms.
  void reset(int num_variables);
  /// Adds D_k(0) = cost0, D_k(1) = cost1.
  void addUnary(int k, double cost0, double cost1);
  /// Adds the pair term of (i, j): c01 when x_i = 0 and x_j = 1, c10 when x_i = 1, x_j = 0.
  void addPair(int i, int j, double c01, double c10);
  /// Minimises E; x[k] = 1 for the variables on the sink side. Deterministic.
  void solve(std::vector<char>& x);

 private:
  using FlowGraph = boost::compressed_sparse_row_graph<boost::directedS>;
  using Arc = boost::graph_traits<FlowGraph>::edge_descriptor;

  void addArcPair(int u, int v, double c, double reverse_c);

  int num_variables_ = 0;
  // Arcs as added (each with its reverse next to it).
  std::vector<int> arc_from_;
  std::vector<int> arc_to_;
  std::vector<double> arc_capacity_;
  // Arcs sorted by tail, and the flow property maps.
  std::vector<int> row_;
  std::vector<int> position_;
  std::vector<std::pair<int, int>> sorted_;
  std::vector<double> capacity_;
  std::vector<double> residual_;
  std::vector<Arc> reverse_;
  std::vector<boost::default_color_type> color_;
  std::vector<long> distance_;
  std::vector<Arc> predecessor_;
};

}  // namespace internal
}  // namespace panmap
