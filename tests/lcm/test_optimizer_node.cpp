// The optimiser process's node over LCM's in-process memq:// provider.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "panmap/lcm/graph_conversions.h"
#include "panmap/lcm/optimizer_node.h"

namespace panmap {
namespace {

struct LabelsInbox {
  std::vector<graph_labels_t> received;
  void onLabels(const lcm::ReceiveBuffer*, const std::string&, const graph_labels_t* msg) {
    received.push_back(*msg);
  }
};

TEST(OptimizerNode, AnswersGraphsAndSurvivesGarbage) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  OptimizerNode node(&lcm, OptimizerNode::Config{});
  LabelsInbox inbox;
  lcm.subscribe("PANMAP_LABELS", &LabelsInbox::onLabels, &inbox);

  // Garbage first: counted, no answer, the node keeps going.
  const uint8_t junk[5] = {1, 2, 3, 4, 5};
  lcm.publish("PANMAP_GRAPH", junk, sizeof(junk));
  while (lcm.handleTimeout(0) > 0) {
  }
  EXPECT_EQ(node.answered(), 0);
  EXPECT_EQ(node.rejected().at("malformed PANMAP_GRAPH"), 1);

  // Two super-points of a chair (class 5), strongly linked.
  SuperpointGraph g;
  g.classes = {1, 5};
  g.background = {1};
  GraphVertex a, b;
  a.id = 1;
  a.instance = 4;
  a.scores = {{5, 10.0}, {1, 1.0}};
  b.id = 2;
  b.instance = 4;
  b.scores = {{5, 8.0}};
  g.vertices = {a, b};
  GraphEdge e;
  e.a = 1;
  e.b = 2;
  e.confidences = {{5, 6.0}};
  g.edges = {e};
  const superpoint_graph_t msg = toMessage(g, 100, 77);
  lcm.publish("PANMAP_GRAPH", &msg);
  while (lcm.handleTimeout(0) > 0) {
  }
  ASSERT_EQ(inbox.received.size(), 1u);
  EXPECT_EQ(inbox.received[0].request_id, 77);
  const GraphLabels labels = fromMessage(inbox.received[0]);
  EXPECT_EQ(labels.semantic.at(1), 5);
  EXPECT_EQ(labels.semantic.at(2), 5);
  EXPECT_EQ(labels.instance.at(1), labels.instance.at(2));
  EXPECT_GT(labels.instance.at(1), 0);
  EXPECT_EQ(node.answered(), 1);

  // The mapper's repeat of the same request (it heard nothing yet) is answered from the cache,
  // with the same labels; another request is solved.
  lcm.publish("PANMAP_GRAPH", &msg);
  while (lcm.handleTimeout(0) > 0) {
  }
  ASSERT_EQ(inbox.received.size(), 2u);
  EXPECT_EQ(node.answered(), 1);
  EXPECT_EQ(node.repeated(), 1);
  EXPECT_EQ(fromMessage(inbox.received[1]).instance, labels.instance);
  const superpoint_graph_t next = toMessage(g, 200, 78);
  lcm.publish("PANMAP_GRAPH", &next);
  while (lcm.handleTimeout(0) > 0) {
  }
  ASSERT_EQ(inbox.received.size(), 3u);
  EXPECT_EQ(inbox.received[2].request_id, 78);
  EXPECT_EQ(node.answered(), 2);
}

}  // namespace
}  // namespace panmap
