#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/lcm/graph_conversions.h"
#include "test_helpers.h"

namespace panmap {
namespace {

SuperpointGraph sampleGraph() {
  SuperpointGraph g;
  g.classes = {1, 2, 5, 22};
  g.background = {1, 2, 22};
  GraphVertex a;
  a.id = 3;
  a.num_voxels = 120;
  a.centroid = Eigen::Vector3d(0.1, -2.5, 1.0 / 3.0);
  a.instance = 7;
  a.semantic = 5;
  a.void_share = 2.0 / 3.0;
  a.scores = {{5, 12.75}, {1, 0.1 + 0.2}};
  GraphVertex b;
  b.id = 9;
  b.scores = {{1, 1e-300}};
  g.vertices = {a, b};
  GraphEdge e;
  e.a = 3;
  e.b = 9;
  e.confidences = {{5, 3.0 / 7.0}};
  g.edges = {e};
  return g;
}

TEST(GraphConversions, GraphRoundTripIsExact) {
  const SuperpointGraph g = sampleGraph();
  const superpoint_graph_t msg = test::throughBytes(toMessage(g, 1234, 42));
  EXPECT_EQ(msg.utime, 1234);
  EXPECT_EQ(msg.request_id, 42);
  const SuperpointGraph back = fromMessage(msg);
  EXPECT_EQ(back.classes, g.classes);
  EXPECT_EQ(back.background, g.background);
  ASSERT_EQ(back.vertices.size(), 2u);
  EXPECT_EQ(back.vertices[0].scores, g.vertices[0].scores);
  EXPECT_EQ(back.vertices[0].centroid, g.vertices[0].centroid);
  EXPECT_EQ(back.vertices[0].instance, 7);
  EXPECT_EQ(back.vertices[0].void_share, 2.0 / 3.0);
  EXPECT_EQ(back.vertices[1].scores, g.vertices[1].scores);
  ASSERT_EQ(back.edges.size(), 1u);
  EXPECT_EQ(back.edges[0].confidences, g.edges[0].confidences);
}

TEST(GraphConversions, LabelsRoundTripIsExact) {
  GraphLabels labels;
  labels.semantic = {{3, 5}, {9, 1}};
  labels.instance = {{3, 7}, {9, 0}};
  labels.instance_confidence = {{7, 0.625f}};
  labels.solve_ms = 12.5;
  const GraphLabels back = fromMessage(test::throughBytes(toMessage(labels, 5, 42)));
  EXPECT_EQ(back.semantic, labels.semantic);
  EXPECT_EQ(back.instance, labels.instance);
  EXPECT_EQ(back.instance_confidence, labels.instance_confidence);
  EXPECT_EQ(back.solve_ms, 12.5);
}

TEST(GraphConversions, InconsistentMessagesAreRefused) {
  superpoint_graph_t msg = toMessage(sampleGraph(), 0, 0);
  superpoint_graph_t bad_edge = msg;
  bad_edge.edges[0].b = 10;
  EXPECT_THROW(fromMessage(bad_edge), Error);
  superpoint_graph_t unsorted = msg;
  std::swap(unsorted.vertices[0], unsorted.vertices[1]);
  EXPECT_THROW(fromMessage(unsorted), Error);
  superpoint_graph_t counts = msg;
  counts.vertices[0].num_scores = 5;
  EXPECT_THROW(fromMessage(counts), Error);
  graph_labels_t labels = toMessage(GraphLabels{}, 0, 0);
  labels.num_superpoints = 2;
  EXPECT_THROW(fromMessage(labels), Error);
}

}  // namespace
}  // namespace panmap
