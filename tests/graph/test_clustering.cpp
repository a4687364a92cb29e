// III-D as clustering by one-mask (P_eps) and two-mask (P_sep) evidence.
#include <map>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/graph/internal/instance_clustering.h"
#include "panmap/graph/optimiser.h"

namespace panmap {
namespace {

GraphVertex vertex(int32_t id, double score, int32_t instance, int32_t cls = 5) {
  GraphVertex v;
  v.id = id;
  v.num_voxels = 100;
  v.instance = instance;
  v.scores = {{cls, score}};
  return v;
}

GraphEdge edge(int32_t a, int32_t b, double same, double apart, int32_t cls = 5) {
  GraphEdge e;
  e.a = a;
  e.b = b;
  if (same > 0.0) e.confidences[cls] = same;
  if (apart > 0.0) e.separations[cls] = apart;
  return e;
}

// Two chairs that touch: A = {1, 2, 3}, B = {4, 5}, each part seen 100 times (P_nu 100).
// Within a chair the parts share a mask (P_eps 60-80) and are rarely apart; across, a merged
// mask now and then (P_eps 15 between 3 and 4) against many frames of two masks (P_sep 40).
// Frame counting put everything into instance 7 (the merged masks won the association).
// Super-point 6 spans the gap: it shares masks with both chairs (25 each) and is apart from
// neither. A table super-point 8 (class 7) touches chair A.
SuperpointGraph twoChairs() {
  SuperpointGraph g;
  g.classes = {1, 5, 7};
  g.background = {1};
  g.vertices = {vertex(1, 100, 7), vertex(2, 100, 7), vertex(3, 100, 7), vertex(4, 100, 7),
                vertex(5, 100, 7), vertex(6, 100, 7), vertex(8, 100, 0, 7)};
  g.edges = {edge(1, 2, 80, 2),  edge(1, 3, 60, 0), edge(2, 3, 70, 1), edge(2, 8, 30, 0, 7),
             edge(3, 4, 15, 40), edge(3, 6, 25, 0), edge(4, 5, 75, 0), edge(4, 6, 25, 0),
             edge(5, 6, 5, 0)};
  return g;
}

std::vector<int32_t> classesOf(const SuperpointGraph& g) {
  std::vector<int32_t> classes;
  for (const GraphVertex& v : g.vertices) classes.push_back(v.scores.begin()->first);
  return classes;
}

TEST(InstanceClustering, SplitsTouchingChairsAndKeepsPartsTogether) {
  const SuperpointGraph g = twoChairs();
  OptimiserConfig config;  // the hand computation below uses these thresholds, not defaults
  config.join_affinity = 0.5;
  config.min_coverage = 0.1;
  const internal::InstanceLabels out = internal::clusterInstances(g, classesOf(g), config);
  // Joins, best affinity first (ties: larger P_eps, then smaller ids): 4-5 (1.0, 75), then
  // 1-3 (1.0, 60); {4, 5} and 6 now share 25 + 5 = 30 against 1-3's 25 with 6: 6 joins B.
  // 5-6 alone (5 of 100 observations) was below min_coverage, but summed it counts. Then
  // {1, 3} + 2 (150 / 153). A = {1, 2, 3} and B = {4, 5, 6}: P_eps 15 + 25 = 40 against
  // P_sep 40, affinity 0.5: the threshold decides.
  EXPECT_EQ(out.instance, (std::vector<int32_t>{7, 7, 7, 7, 7, 7, 8}));
  config.join_affinity = 0.6;
  const internal::InstanceLabels apart = internal::clusterInstances(g, classesOf(g), config);
  // The larger cluster (by voxels, then first member) keeps the initial id 7; B and the
  // table get new ids above it, in order of class.
  EXPECT_EQ(apart.instance, (std::vector<int32_t>{7, 7, 7, 8, 8, 8, 9}));
}

TEST(InstanceClustering, AFewSharedMasksAmongManyViewsJoinNothing) {
  // Two chairs never seen apart (one hides the other), under one mask once: P_eps 5 against
  // P_nu 100 each is below min_coverage 0.1.
  SuperpointGraph g;
  g.classes = {5};
  g.vertices = {vertex(1, 100, 3), vertex(2, 100, 4)};
  g.edges = {edge(1, 2, 5, 0)};
  OptimiserConfig config;
  config.min_coverage = 0.1;
  EXPECT_EQ(internal::clusterInstances(g, {5, 5}, config).instance,
            (std::vector<int32_t>{3, 4}));
  g.edges = {edge(1, 2, 20, 0)};
  EXPECT_EQ(internal::clusterInstances(g, {5, 5}, config).instance,
            (std::vector<int32_t>{3, 3}));
}

// Candidate joins wait in a heap; a join changes what the waiting ones stand on. Super-points
// 1 (P_nu 10), 2 (1000) and 3: 1-2 share masks strongly (P_eps 100) and join first; 1-3 share
// one (P_eps 1, affinity 1), enough for 1 alone (1 >= 0.05 x 10).
TEST(InstanceClustering, AJoinRechecksTheLinksWaitingOnIt) {
  OptimiserConfig config;
  config.join_affinity = 0.6;
  config.min_coverage = 0.05;
  SuperpointGraph g;
  g.classes = {5};
  // 3 seen 1000 times: once 1 holds 2, the link covers 1 / min(1010, 1000), under 5 %.
  g.vertices = {vertex(1, 10, 3), vertex(2, 1000, 3), vertex(3, 1000, 4)};
  g.edges = {edge(1, 2, 100, 0), edge(1, 3, 1, 0)};
  EXPECT_EQ(internal::clusterInstances(g, {5, 5, 5}, config).instance,
            (std::vector<int32_t>{3, 3, 4}));
  // 3 seen 10 times, but 2 and 3 were two objects in 100 frames: the join sums that into the
  // 1-3 link (affinity 1 / 101), whose waiting entry no longer holds.
  g.vertices = {vertex(1, 10, 3), vertex(2, 1000, 3), vertex(3, 10, 4)};
  g.edges = {edge(1, 2, 100, 0), edge(1, 3, 1, 0), edge(2, 3, 0, 100)};
  EXPECT_EQ(internal::clusterInstances(g, {5, 5, 5}, config).instance,
            (std::vector<int32_t>{3, 3, 4}));
  // Without the join 1 and 3 do join (2 alone gets a new id: 3 is taken).
  g.edges = {edge(1, 3, 1, 0)};
  EXPECT_EQ(internal::clusterInstances(g, {5, 5, 5}, config).instance,
            (std::vector<int32_t>{3, 5, 3}));
}

TEST(InstanceClustering, StuffGetsNoInstanceAndOptimiseUsesIt) {
  SuperpointGraph g = twoChairs();
  g.vertices.push_back(vertex(9, 100, 2, 1));  // a wall
  OptimiserConfig config;
  config.join_affinity = 0.6;
  config.objects.consolidate = false;
  const GraphLabels labels = optimise(g, config);
  EXPECT_EQ(labels.instance.at(9), 0);
  EXPECT_EQ(labels.instance.at(1), labels.instance.at(3));
  EXPECT_NE(labels.instance.at(1), labels.instance.at(4));
  EXPECT_EQ(labels.instance.at(4), labels.instance.at(6));
}

TEST(InstanceClustering, ConfigIsChecked) {
  OptimiserConfig config;
  config.join_affinity = 1.5;
  EXPECT_THROW(config.check(), Error);
  config.join_affinity = 0.5;
  config.min_coverage = -0.1;
  EXPECT_THROW(config.check(), Error);
}

}  // namespace
}  // namespace panmap
