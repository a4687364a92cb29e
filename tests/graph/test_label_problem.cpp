// buildLabelProblem on a hand-made graph: the label space, the unaries and normalised scores
// of Eq. 8 per (vertex, label), the initial argmax labels, and the per-label tables they live in.
#include <cmath>

#include <gtest/gtest.h>

#include "graph_builders.h"
#include "panmap/graph/internal/semantic_energy.h"

namespace panmap {
namespace internal {
namespace {

using test::vertex;

TEST(LabelProblem, UnariesAndScoresPerVertexAndLabel) {
  SuperpointGraph graph;
  graph.classes = {3, 5, 8};  // 8 is scored nowhere and no vertex's argmax: left out
  graph.vertices = {vertex(1, 4, {{3, 3.0}, {5, 1.0}}), vertex(2, 1, {{5, 2.0}}), vertex(3, 2, {})};
  OptimiserConfig config;
  config.weighting = OptimiserConfig::Weighting::kSurface;  // unary times the voxels
  config.score_floor = 1e-6;
  const LabelProblem problem = buildLabelProblem(graph, config);
  ASSERT_EQ(problem.labels, (std::vector<int32_t>{3, 5}));
  ASSERT_EQ(problem.num_vertices, 3);
  // Vertex 1: 3/4 class 3, 1/4 class 5, 4 voxels.
  EXPECT_DOUBLE_EQ(problem.score(0, 0), 0.75);
  EXPECT_DOUBLE_EQ(problem.score(0, 1), 0.25);
  EXPECT_DOUBLE_EQ(problem.unary(0, 0), 4 * -std::log(0.75));
  EXPECT_DOUBLE_EQ(problem.unary(0, 1), 4 * -std::log(0.25));
  // Vertex 2: class 5 only; class 3 costs the floor.
  EXPECT_DOUBLE_EQ(problem.score(1, 0), 0.0);
  EXPECT_DOUBLE_EQ(problem.score(1, 1), 1.0);
  EXPECT_DOUBLE_EQ(problem.unary(1, 0), -std::log(1e-6));
  EXPECT_DOUBLE_EQ(problem.unary(1, 1), 0.0);
  // Vertex 3: no scores, every label free; it starts at the smallest class.
  EXPECT_DOUBLE_EQ(problem.unary(2, 0), 0.0);
  EXPECT_DOUBLE_EQ(problem.unary(2, 1), 0.0);
  EXPECT_EQ(problem.initial, (std::vector<int>{0, 1, 0}));
  // A label's row holds its values by vertex.
  const double* unary_5 = problem.unary.row(1);
  EXPECT_DOUBLE_EQ(unary_5[0], problem.unary(0, 1));
  EXPECT_DOUBLE_EQ(unary_5[1], problem.unary(1, 1));
}

TEST(LabelTable, RowsAreIndependent) {
  LabelTable table;
  table.assign(3, 2, 1.5);
  table(2, 0) = 7.0;
  table.row(1)[0] = -2.0;
  EXPECT_DOUBLE_EQ(table(2, 0), 7.0);
  EXPECT_DOUBLE_EQ(table(2, 1), 1.5);
  EXPECT_DOUBLE_EQ(table(0, 1), -2.0);
  EXPECT_DOUBLE_EQ(table(0, 0), 1.5);
  table.assign(1, 1, 0.0);
  EXPECT_DOUBLE_EQ(table(0, 0), 0.0);
}

}  // namespace
}  // namespace internal
}  // namespace panmap
