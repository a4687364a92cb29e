// Objects out of the final instances: fragments folded into their best-linked neighbour or
// left out, the evidence of each instance, and the logistic confidence.
#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "graph_builders.h"
#include "panmap/core/error.h"
#include "panmap/graph/instance_evidence.h"
#include "panmap/graph/internal/object_consolidation.h"
#include "panmap/graph/object_confidence.h"
#include "panmap/graph/optimiser.h"

namespace panmap {
namespace {

using test::edge;
using test::vertex;

// 2 cm voxels, min area 0.04 m2 = 100 voxels. Chairs (class 5): instance 1 = super-points
// {1, 2} (150 + 100 voxels), fragment 2 = {3} (40) linked to 1 (3.0) and to fragment 3 (5.0),
// fragment 3 = {4} (30) linked to 1 (4.0), fragment 4 = {5} (60) with no link, fragments
// 5 = {6} (70) and 6 = {7} (50) linked only to each other, a table fragment 7 = {8} (20) linked
// to chair instance 1 by a table edge (class 7) only.
struct Case {
  SuperpointGraph graph;
  std::vector<int32_t> classes = {5, 5, 5, 5, 5, 5, 5, 7};
  std::vector<int32_t> instances = {1, 1, 2, 3, 4, 5, 6, 7};
  Case() {
    graph.voxel_size_m = 0.02;
    graph.classes = {5, 7};
    graph.vertices = {vertex(1, 150, {{5, 1500.0}, {7, 500.0}}),
                      vertex(2, 100, {{5, 1000.0}}),
                      vertex(3, 40, {{5, 40.0}}),
                      vertex(4, 30, {{5, 30.0}}),
                      vertex(5, 60, {{5, 60.0}}),
                      vertex(6, 70, {{5, 70.0}}),
                      vertex(7, 50, {{5, 50.0}}),
                      vertex(8, 20, {{7, 20.0}})};
    graph.edges = {edge(1, 2, {{5, 9.0}}), edge(1, 3, {{5, 3.0}}), edge(2, 4, {{5, 4.0}}),
                   edge(2, 8, {{7, 6.0}}), edge(3, 4, {{5, 5.0}}), edge(6, 7, {{5, 2.0}})};
  }
};

TEST(InstanceEvidence, SumsScoresVoxelsAndLinks) {
  const Case c;
  const std::vector<InstanceEvidence> e = instanceEvidence(c.graph, c.classes, c.instances);
  ASSERT_EQ(e.size(), 7u);
  EXPECT_EQ(e[0].instance, 1);
  EXPECT_EQ(e[0].superpoints, 2);
  EXPECT_EQ(e[0].voxels, 250);
  EXPECT_DOUBLE_EQ(e[0].score, 2500.0);
  EXPECT_DOUBLE_EQ(e[0].score_all, 3000.0);
  EXPECT_DOUBLE_EQ(e[0].support(), 10.0);
  EXPECT_DOUBLE_EQ(e[0].classShare(), 2500.0 / 3000.0);
  EXPECT_DOUBLE_EQ(e[0].inner_link, 9.0);
  EXPECT_DOUBLE_EQ(e[0].outer_link, 4.0);  // to 3 (the table edge is another class)
  EXPECT_DOUBLE_EQ(e[1].outer_link, 5.0);  // fragment 2: to 3
  EXPECT_EQ(e[6].class_id, 7);
  EXPECT_DOUBLE_EQ(e[6].outer_link, 0.0);
  EXPECT_THROW(instanceEvidence(c.graph, c.classes, {1, 2}), Error);
}

TEST(ObjectConsolidation, FoldsLinkedFragmentsAndDropsLoneOnes) {
  const Case c;
  OptimiserConfig::Objects config;
  const internal::ConsolidatedObjects out =
      internal::consolidateObjects(c.graph, c.classes, c.instances, config);
  // 2 and 3 link to each other (5.0) more strongly than to 1 (3.0, 4.0), but a fragment
  // prefers a larger instance: both folded into 1. 4: no link, dropped.
  // 5 <-> 6: 120 voxels together, kept as 5 (the larger). 7 (table): its only link is of
  // class 7 to a chair super-point, not an instance of its class: dropped.
  EXPECT_EQ(out.instance, (std::vector<int32_t>{1, 1, 1, 1, 0, 5, 5, 0}));
  EXPECT_EQ(out.folded, 3);   // 2, 3 and 6
  EXPECT_EQ(out.dropped, 2);  // 4 and 7
  ASSERT_EQ(out.confidence.size(), 2u);
  ASSERT_EQ(out.evidence.size(), 2u);
  // Instance 1 now: 320 voxels = 0.128 m2, score 2570 of 3070.
  EXPECT_FLOAT_EQ(out.evidence.at(1).area_m2, static_cast<float>(320 * 0.0004));
  EXPECT_FLOAT_EQ(out.evidence.at(1).support, static_cast<float>(2570.0 / 320.0));
  EXPECT_FLOAT_EQ(out.evidence.at(1).class_share, static_cast<float>(2570.0 / 3070.0));
  const double z = config.bias + config.area * std::log10(320 * 0.0004) +
                   config.support * std::log2(2570.0 / 320.0) + config.share * 2570.0 / 3070.0;
  EXPECT_FLOAT_EQ(out.confidence.at(1), static_cast<float>(1.0 / (1.0 + std::exp(-z))));
}

TEST(ObjectConsolidation, OffOrWithoutAVoxelSizeKeepsEveryInstance) {
  Case c;
  OptimiserConfig::Objects config;
  config.consolidate = false;
  internal::ConsolidatedObjects out =
      internal::consolidateObjects(c.graph, c.classes, c.instances, config);
  EXPECT_EQ(out.instance, c.instances);
  EXPECT_EQ(out.confidence.size(), 7u);
  config.consolidate = true;
  c.graph.voxel_size_m = 0.0;  // a graph from before voxel sizes were sent: nothing to measure
  out = internal::consolidateObjects(c.graph, c.classes, c.instances, config);
  EXPECT_EQ(out.instance, c.instances);
  EXPECT_EQ(out.folded + out.dropped, 0);
}

TEST(ObjectConsolidation, ConfidenceRisesWithAreaSupportAndShare) {
  OptimiserConfig::Objects config;
  config.share = 1.0;  // the default holds it at 0
  InstanceEvidence e;
  e.voxels = 1000;
  e.score = 8000.0;
  e.score_all = 10000.0;
  const float base = objectConfidence(e, 0.02, config);
  InstanceEvidence larger = e, seen_more = e, purer = e;
  larger.voxels = 4000, larger.score = 32000.0, larger.score_all = 40000.0;
  seen_more.score = 16000.0, seen_more.score_all = 18000.0;
  purer.score_all = 8000.0;
  EXPECT_GT(objectConfidence(larger, 0.02, config), base);
  EXPECT_GT(objectConfidence(seen_more, 0.02, config), base);
  EXPECT_GT(objectConfidence(purer, 0.02, config), base);
  InstanceEvidence empty;  // no voxels, no scores: finite, low
  const float none = objectConfidence(empty, 0.02, config);
  EXPECT_TRUE(std::isfinite(none));
  EXPECT_LT(none, base);
}

TEST(ObjectConsolidation, ConfigIsChecked) {
  OptimiserConfig config;
  config.objects.min_area_m2 = -1.0;
  EXPECT_THROW(config.check(), Error);
  config.objects.min_area_m2 = 0.04;
  config.objects.support = NAN;
  EXPECT_THROW(config.check(), Error);
}

}  // namespace
}  // namespace panmap
