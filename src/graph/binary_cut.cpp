// Exact binary minimisation by one s-t minimum cut (Kolmogorov, Zabih, "What energy functions
// can be minimized via graph cuts?", PAMI 2004), with Boost Graph's Boykov-Kolmogorov max-flow.
//
// Variable k is node k; x_k = 0 is the source side, 1 the sink side. D_k(1) is the capacity
// source->k (cut when k is on the sink side), D_k(0) the capacity k->sink; both are shifted by
// min(D_k(0), D_k(1)), a constant. A pair term is the arc i->j of capacity c01 (cut when i is on
// the source side and j on the sink side) and j->i of capacity c10.
//
// Why Boost and not OpenCV's cv::detail::GCGraph (opencv2/imgproc/detail/gcgraph.hpp):
// GCGraph::inSourceSegment() reports a node by its last search-tree flag, also for nodes that
// were orphaned and left free, so its labelling is not always a minimum cut (a 5-vertex swap
// move in our tests had max flow 14.02 but a reported cut of energy 32.92). Boost's colour map
// marks the source tree black; at termination that is exactly the set reachable from the source
// in the residual graph, whose cut is minimum. Every other node takes 1.
#include "panmap/graph/internal/binary_cut.h"

#include <algorithm>

// GCC reports false -Wmaybe-uninitialized positives inside Boost's max-flow when inlined here.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#include <boost/property_map/property_map.hpp>
#pragma GCC diagnostic pop

namespace panmap {
namespace internal {

void BinaryCut::reset(int num_variables) {
  num_variables_ = num_variables;
  arc_from_.clear();
  arc_to_.clear();
  arc_capacity_.clear();
}

void BinaryCut::addArcPair(int u, int v, double c, double reverse_c) {
  arc_from_.push_back(u);
  arc_from_.push_back(v);
  arc_to_.push_back(v);
  arc_to_.push_back(u);
  arc_capacity_.push_back(c);
  arc_capacity_.push_back(reverse_c);
}

void BinaryCut::addUnary(int k, double cost0, double cost1) {
  const double shift = std::min(cost0, cost1);
  if (cost1 > shift) addArcPair(num_variables_, k, cost1 - shift, 0.0);
  if (cost0 > shift) addArcPair(k, num_variables_ + 1, cost0 - shift, 0.0);
}

void BinaryCut::addPair(int i, int j, double c01, double c10) {
  if (c01 > 0.0 || c10 > 0.0) addArcPair(i, j, c01, c10);
}

void BinaryCut::solve(std::vector<char>& x) {
  const int nodes = num_variables_ + 2;
  const int source = num_variables_;
  const int sink = num_variables_ + 1;
  // Counting sort of the arcs by tail; arcs 2i and 2i + 1 are each other's reverse.
  const size_t arcs = arc_from_.size();
  row_.assign(nodes + 1, 0);
  for (int u : arc_from_) ++row_[u + 1];
  for (int u = 0; u < nodes; ++u) row_[u + 1] += row_[u];
  position_.resize(arcs);
  for (size_t i = 0; i < arcs; ++i) position_[i] = row_[arc_from_[i]]++;
  sorted_.resize(arcs);
  capacity_.resize(arcs);
  residual_.assign(arcs, 0.0);
  reverse_.resize(arcs);
  for (size_t i = 0; i < arcs; ++i) {
    const int at = position_[i];
    sorted_[at] = {arc_from_[i], arc_to_[i]};
    capacity_[at] = arc_capacity_[i];
    reverse_[at] = Arc(arc_to_[i], position_[i ^ 1]);
  }
  const FlowGraph graph(boost::edges_are_sorted, sorted_.begin(), sorted_.end(), nodes);
  color_.assign(nodes, boost::white_color);
  distance_.assign(nodes, 0);
  predecessor_.assign(nodes, Arc());
  const auto arc_index = boost::get(boost::edge_index, graph);
  const auto node_index = boost::get(boost::vertex_index, graph);
  boost::boykov_kolmogorov_max_flow(
      graph, boost::make_iterator_property_map(capacity_.begin(), arc_index),
      boost::make_iterator_property_map(residual_.begin(), arc_index),
      boost::make_iterator_property_map(reverse_.begin(), arc_index),
      boost::make_iterator_property_map(predecessor_.begin(), node_index),
      boost::make_iterator_property_map(color_.begin(), node_index),
      boost::make_iterator_property_map(distance_.begin(), node_index), node_index, source, sink);
  x.resize(num_variables_);
  for (int k = 0; k < num_variables_; ++k) x[k] = color_[k] != boost::black_color;
}

}  // namespace internal
}  // namespace panmap
