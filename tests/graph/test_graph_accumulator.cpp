#include <functional>
#include <random>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/graph/graph_accumulator.h"
#include "panmap/map/projective_integrator.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "panmap/superpoint/vote_split.h"
#include "test_meshes.h"

namespace panmap {
namespace {

// A wall at x = 2 seen head-on, split into image columns by hand-made surfaces and masks.
class WallGraph : public ::testing::Test {
 protected:
  WallGraph() : renderer_(wall()), pool_(1), integrator_(IntegratorConfig{}, &pool_) {
    T_W_C_ = test::lookAt({0, 0, 1}, {2, 0, 1});
    DepthNoiseConfig exact;
    exact.enabled = false;
    frame_.camera = test::kinectCamera();
    frame_.depth = simulateDepth(renderer_.render(frame_.camera, T_W_C_), exact, 0);
  }
  static LabelledMesh wall() {
    LabelledMesh mesh;
    test::addQuad(&mesh, {2, -4, -2}, {2, 4, -2}, {2, 4, 4}, {2, -4, 4}, 1, 1, 8);
    return mesh;
  }
  // Surfaces by column: [0, s1), [s1, s2), [s2, 640) with the given categories.
  FrameSegmentation columns(int s1, int s2, int32_t c1, int32_t c2, int32_t c3) const {
    FrameSegmentation seg;
    seg.geometric = LabelImage(640, 480, 1);
    seg.surfaces = LabelImage(640, 480, 0);
    int count[3] = {0, 0, 0};
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        const int k = u < s1 ? 0 : (u < s2 ? 1 : 2);
        seg.surfaces(u, v) = k + 1;
        ++count[k];
      }
    }
    const int32_t cats[3] = {c1, c2, c3};
    for (int k = 0; k < 3; ++k) {
      if (count[k])
        seg.surface_list.push_back(Surface{k + 1, 1, k + 1, cats[k], true, 0.9f, count[k]});
    }
    return seg;
  }
  // One mask over the whole image (class 5, score 0.8).
  static PanopticFrame wholeMask(int32_t category = 5, bool thing = true) {
    PanopticFrame p;
    p.segment_ids = LabelImage(640, 480, 1);
    p.segments = {PanopticSegment{1, category, category, thing, 0.8f}};
    return p;
  }
  void step(SuperpointTracker* tracker, TsdfMap* map, const FrameSegmentation& seg) {
    const FrameAssociation a = tracker->associate(seg, frame_, T_W_C_, *map);
    integrator_.integrate(frame_, T_W_C_, &a.pixel_labels, map);
  }

  MeshRenderer renderer_;
  ThreadPool pool_;
  ProjectiveIntegrator integrator_;
  Eigen::Isometry3d T_W_C_;
  RgbdFrame frame_;
};

TEST_F(WallGraph, ScoresFollowEquationFiveAndEdgesEquationSix) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointTracker tracker(SuperpointConfig{});
  step(&tracker, &map, columns(384, 640, 1, 4, 0));  // labels 1 (60 %) and 2 (40 %)
  GraphAccumulator graph(GraphConfig{});
  graph.update(frame_, T_W_C_, wholeMask(), map, tracker);
  const double s1 = graph.scores(1).at(5), s2 = graph.scores(2).at(5);
  // P_o * N^S_o with N the unique voxels: whole multiples of 0.8, split about 60 / 40.
  EXPECT_NEAR(s1 / 0.8, std::round(s1 / 0.8), 1e-6);
  EXPECT_NEAR(s1 / (s1 + s2), 0.6, 0.05);
  // P_eps = P_o * P_s * min(N1, N2), P_s = 1 / (1 + d / 0.5 m). The wall seen at 2 m spans
  // y in [-1.217, 1.217] m; column 384 is at y = 0.246 m, so the parts' centroids are
  // (1.217 + 0.246) / 2 + (1.217 - 0.246) / 2 = 1.217 m apart: P_s = 0.291.
  const double e = graph.confidences(1, 2).at(5);
  const double p_s = e / (0.8 * std::min(s1, s2) / 0.8);
  EXPECT_NEAR(p_s, 1.0 / (1.0 + 1.217 / 0.5), 0.01);
  // A second identical frame doubles everything.
  graph.update(frame_, T_W_C_, wholeMask(), map, tracker);
  EXPECT_DOUBLE_EQ(graph.scores(1).at(5), 2 * s1);
  EXPECT_DOUBLE_EQ(graph.confidences(2, 1).at(5), 2 * e);
  // Stuff masks count with P_o = 0.5, whatever their score.
  GraphAccumulator stuff(GraphConfig{});
  stuff.update(frame_, T_W_C_, wholeMask(1, false), map, tracker);
  EXPECT_DOUBLE_EQ(stuff.scores(1).at(1), s1 / 0.8 * 0.5);
}

TEST_F(WallGraph, MergedSuperpointsAddTheirScoresAndEdges) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointConfig spatial;
  spatial.semantic_consistency = false;
  SuperpointTracker tracker(spatial);
  GraphAccumulator graph(GraphConfig{});
  // Three super-points side by side (1 | 2 | 3); observed twice with one mask over all.
  for (int k = 0; k < 2; ++k) {
    step(&tracker, &map, columns(256, 448, 1, 4, 7));
    graph.update(frame_, T_W_C_, wholeMask(), map, tracker);
  }
  ASSERT_EQ(tracker.labels().size(), 3);
  const auto s1 = graph.scores(1), s2 = graph.scores(2), s3 = graph.scores(3);
  const double e12 = graph.confidences(1, 2).at(5), e13 = graph.confidences(1, 3).at(5);
  const double e23 = graph.confidences(2, 3).at(5);
  // Surfaces spanning 1 and 2 (alternating with the three-way split so 2 survives) until
  // spatial-only merging joins them.
  for (int k = 0; k < 8 && tracker.merges().empty(); ++k) {
    step(&tracker, &map, k % 2 ? columns(448, 640, 1, 7, 0) : columns(256, 448, 1, 4, 7));
  }
  ASSERT_EQ(tracker.merges().size(), 1u);
  ASSERT_EQ(tracker.merges()[0].kept, 1);
  ASSERT_EQ(tracker.merges()[0].removed, 2);
  // An update with no usable mask only folds the merge in.
  PanopticFrame none = wholeMask();
  none.segments.clear();
  graph.update(frame_, T_W_C_, none, map, tracker);
  EXPECT_DOUBLE_EQ(graph.scores(1).at(5), s1.at(5) + s2.at(5));
  EXPECT_TRUE(graph.scores(2).empty());
  EXPECT_TRUE(graph.confidences(1, 2).empty());  // inside the merged super-point now
  EXPECT_DOUBLE_EQ(graph.confidences(1, 3).at(5), e13 + e23);
  EXPECT_DOUBLE_EQ(graph.scores(3).at(5), s3.at(5));
  (void)e12;
  const SuperpointGraph g = graph.graph(map, tracker);
  ASSERT_EQ(g.edges.size(), 1u);
  EXPECT_EQ(g.edges[0].a, 1);
  EXPECT_EQ(g.edges[0].b, 3);
  for (const GraphVertex& v : g.vertices) EXPECT_NE(v.id, 2);
}

// A super-point formed under one mask, then shown as two masks of its class: the tracker
// splits it (mask_verdicts), and the graph gives the new super-point its share of the scores
// and the pair the one-mask history as P_eps (P_s min(share, 1 - share) of the scores).
TEST_F(WallGraph, SplitSuperpointsShareTheirScoresAndKeepTheirHistory) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointConfig config;
  config.mask_verdicts = true;
  SuperpointTracker tracker(config);
  GraphAccumulator graph(GraphConfig{});
  for (int k = 0; k < 2; ++k) {
    step(&tracker, &map, columns(640, 640, 5, 0, 0));  // one surface, one mask
    graph.update(frame_, T_W_C_, wholeMask(), map, tracker);
  }
  const double before = graph.scores(1).at(5);
  const FrameSegmentation two = columns(384, 640, 5, 5, 0);
  FrameAssociation a = tracker.associate(two, frame_, T_W_C_, map);
  ASSERT_EQ(a.splits.size(), 1u);
  EXPECT_GT(applySplits(&a, two, frame_, T_W_C_, tracker.labels(), &map), 0u);
  const double share = a.splits[0].share;
  EXPECT_NEAR(share, 0.4, 0.01);  // the right 256 of 640 columns
  // The parts' centroids are 1.217 m apart (ScoresFollowEquationFiveAndEdgesEquationSix).
  EXPECT_NEAR(a.splits[0].distance_m, 1.217, 0.01);
  const double p_s = 1.0 / (1.0 + a.splits[0].distance_m / GraphConfig{}.spatial_scale_m);
  graph.applySplits(a.splits, tracker);
  EXPECT_DOUBLE_EQ(graph.scores(2).at(5), share * before);
  EXPECT_DOUBLE_EQ(graph.scores(1).at(5), before - share * before);
  EXPECT_DOUBLE_EQ(graph.confidences(1, 2).at(5), p_s * share * before);
  EXPECT_TRUE(graph.separations(1, 2).empty());
}

// Two chair masks side by side over super-points 1 and 2: the network saw two objects. Each
// pair under two masks of one thing class gets P_sep^C (with P_s), and P_apart (without P_s)
// once the pair has been under one mask; stuff masks only count towards P_apart.
TEST_F(WallGraph, TwoMasksGiveSeparationAndApartEvidence) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointTracker tracker(SuperpointConfig{});
  step(&tracker, &map, columns(384, 640, 5, 5, 0));  // super-points 1 (60 %) and 2 (40 %)
  // A gap without mask keeps each mask's rays on its own super-point's voxels.
  PanopticFrame two;
  two.segment_ids = LabelImage(640, 480, 0);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) two.segment_ids(u, v) = u < 340 ? 1 : (u >= 430 ? 2 : 0);
  }
  two.segments = {PanopticSegment{1, 5, 5, true, 0.8f}, PanopticSegment{2, 5, 5, true, 0.6f}};
  GraphAccumulator graph(GraphConfig{});
  graph.update(frame_, T_W_C_, two, map, tracker);
  const double s1 = graph.scores(1).at(5) / 0.8, s2 = graph.scores(2).at(5) / 0.6;  // N^S_o
  EXPECT_TRUE(graph.confidences(1, 2).empty());  // never under one mask
  // P_sep^5 = min(0.8, 0.6) * P_s * min(N1, N2), P_s as in Eq. 6 (centroids 1.217 m apart).
  // Columns 340 and 430 are at y = 0.187 and -0.104 m: centroids 1.394 m apart.
  const double p_s = 1.0 / (1.0 + 1.394 / 0.5);
  EXPECT_NEAR(graph.separations(1, 2).at(5), 0.6 * p_s * std::min(s1, s2), 0.02 * s2);
  EXPECT_EQ(graph.apart(1, 2), 0.0);  // no P_eps to weigh it against yet
  // One mask over both, then two masks again: P_apart now grows, without P_s.
  graph.update(frame_, T_W_C_, wholeMask(), map, tracker);
  graph.update(frame_, T_W_C_, two, map, tracker);
  // P_o are floats: 0.6f, not 0.6.
  EXPECT_NEAR(graph.apart(1, 2), 0.6 * std::min(s1, s2), 1e-6 * s2);
  EXPECT_NEAR(graph.separations(1, 2).at(5), 2 * 0.6 * p_s * std::min(s1, s2), 0.04 * s2);
  // A wall (stuff) mask beside a chair mask: P_apart only.
  PanopticFrame mixed = two;
  mixed.segments[1] = PanopticSegment{2, 1, 1, false, 1.0f};
  const double before = graph.separations(1, 2).at(5);
  graph.update(frame_, T_W_C_, mixed, map, tracker);
  EXPECT_DOUBLE_EQ(graph.separations(1, 2).at(5), before);
  EXPECT_NEAR(graph.apart(1, 2), 1.1 * std::min(s1, s2), 1e-6 * s2);
  const SuperpointGraph g = graph.graph(map, tracker);
  ASSERT_EQ(g.edges.size(), 1u);
  EXPECT_DOUBLE_EQ(g.edges[0].apart, graph.apart(1, 2));
  EXPECT_DOUBLE_EQ(g.edges[0].separations.at(5), before);
  EXPECT_EQ(g.edges[0].confidences.count(0), 0u);  // the keys below 1 stay out of P_eps
}

// A network's outline errors put a band of each mask on its neighbour: those pixels vote
// (Eq. 5) but tie nothing (Eq. 6) unless they lie pair_interior_px inside the mask.
TEST_F(WallGraph, CoObservationLeavesOutTheBandAlongAMasksOutline) {
  TsdfMap map(TsdfMap::Config{0.05f});
  SuperpointTracker tracker(SuperpointConfig{});
  step(&tracker, &map, columns(384, 640, 5, 1, 0));  // a chair part (1) and a wall part (2)
  // The chair mask reaches 16 px onto the wall part; the wall mask has the rest.
  PanopticFrame bleed;
  bleed.segment_ids = LabelImage(640, 480, 0);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) bleed.segment_ids(u, v) = u < 400 ? 1 : 2;
  }
  bleed.segments = {PanopticSegment{1, 5, 5, true, 0.8f}, PanopticSegment{2, 1, 1, false, 1.0f}};
  GraphConfig every, inside;
  every.pair_interior_px = 0;
  inside.pair_interior_px = 20;
  GraphAccumulator a(every), b(inside);
  a.update(frame_, T_W_C_, bleed, map, tracker);
  b.update(frame_, T_W_C_, bleed, map, tracker);
  // Every pixel (the paper): the band ties the wall part to the chair as if one mask held both.
  ASSERT_EQ(a.confidences(1, 2).count(5), 1u);
  EXPECT_GT(a.confidences(1, 2).at(5), 0.0);
  // 20 px inside the outline: no tie, and the same votes.
  EXPECT_TRUE(b.confidences(1, 2).empty());
  ASSERT_GT(a.scores(2).count(5), 0u);
  EXPECT_EQ(b.scores(1), a.scores(1));
  EXPECT_EQ(b.scores(2), a.scores(2));
  // A mask over both parts, far from its outline, still ties them.
  b.update(frame_, T_W_C_, wholeMask(), map, tracker);
  ASSERT_EQ(b.confidences(1, 2).count(5), 1u);
  EXPECT_GT(b.confidences(1, 2).at(5), 0.0);
  // A segment id beyond what a hit key holds is named, and nothing is added.
  PanopticFrame huge = wholeMask();
  huge.segments[0].id = internal::kMaxMaskHitId + 1;
  const auto before = b.scores(1);
  EXPECT_THROW(b.update(frame_, T_W_C_, huge, map, tracker), Error);
  EXPECT_EQ(b.scores(1), before);
}

TEST(GraphAccumulator, RejectsBadInput) {
  GraphConfig bad;
  bad.spatial_scale_m = 0.0;
  EXPECT_THROW(GraphAccumulator{bad}, Error);
  GraphConfig band;
  band.pair_interior_px = -1;
  EXPECT_THROW(GraphAccumulator{band}, Error);
}

}  // namespace
}  // namespace panmap

namespace panmap {
namespace {

// Scores and edges of super-points no voxel votes for are dropped, the rest kept exactly.
TEST(GraphAccumulator, ForgetsSuperpointsWithoutVotes) {
  GraphAccumulator graph{GraphConfig{}};
  GraphAccumulator::Snapshot s;
  s.scores[1][5] = 2.5;
  s.scores[3][7] = 1.0;
  s.scores[4][5] = 0.5;
  s.edges[{1, 3}][5] = 0.7;
  s.edges[{1, 4}][5] = 0.9;
  graph.restore(s);
  LabelRegistry registry;
  for (int i = 0; i < 4; ++i) registry.create();
  graph.forgetUnvoted({0, 1, 0, 0, 1}, registry);
  const GraphAccumulator::Snapshot after = graph.snapshot();
  ASSERT_EQ(2u, after.scores.size());
  EXPECT_EQ(2.5, after.scores.at(1).at(5));
  EXPECT_EQ(0.5, after.scores.at(4).at(5));
  ASSERT_EQ(1u, after.edges.size());
  EXPECT_EQ(0.9, after.edges.at({1, 4}).at(5));
}

// The final graph of `merged_into` (a label's parent, <= it) and 6,000 random stored edges
// among 400 labels, built without threads and with two: equal edge for edge.
void expectThreadsGiveOnePass(const std::function<int32_t(int32_t)>& merged_into,
                              size_t min_edges) {
  constexpr int32_t kLabels = 400;
  SuperpointTracker::Snapshot tracked;
  tracked.parents.resize(kLabels + 1);
  for (int32_t l = 0; l <= kLabels; ++l) {
    tracked.parents[l] = l == 0 ? 0 : merged_into(l);
    if (l > 0 && tracked.parents[l] == l) tracked.states[l].class_counts[5] = 1.0;
  }
  SuperpointTracker tracker{SuperpointConfig{}};
  tracker.restore(tracked);
  GraphAccumulator::Snapshot state;
  std::mt19937 rng(11);
  std::uniform_int_distribution<int32_t> label(1, kLabels), cls(-3, 4);
  std::uniform_real_distribution<double> value(0.01, 1.0);
  while (state.edges.size() < 6000) {
    const int32_t a = label(rng), b = label(rng);
    if (a >= b) continue;
    auto& classes = state.edges[{a, b}];
    for (int k = 0; k < 2; ++k) classes[cls(rng)] += value(rng);
  }
  GraphConfig config;
  config.prune_edges = false;  // an empty map owns no surface: keep every edge
  GraphAccumulator one(config);
  one.restore(state);
  ThreadPool pool(2);
  GraphAccumulator two(config, &pool);
  two.restore(state);
  const TsdfMap map(TsdfMap::Config{0.05f});
  const SuperpointGraph g1 = one.graph(map, tracker), g2 = two.graph(map, tracker);
  ASSERT_GE(g1.edges.size(), min_edges);
  ASSERT_LT(g1.edges.size(), state.edges.size());  // merged pairs were summed into one
  ASSERT_EQ(g1.edges.size(), g2.edges.size());
  for (size_t i = 0; i < g1.edges.size(); ++i) {
    const GraphEdge &e1 = g1.edges[i], &e2 = g2.edges[i];
    EXPECT_EQ(e1.a, e2.a);
    EXPECT_EQ(e1.b, e2.b);
    EXPECT_EQ(e1.confidences, e2.confidences);
    EXPECT_EQ(e1.separations, e2.separations);
    EXPECT_EQ(e1.apart, e2.apart);
    EXPECT_TRUE(tracker.labels().isRoot(e1.a) && tracker.labels().isRoot(e1.b));
    if (i > 0) {
      EXPECT_LT(std::tie(g1.edges[i - 1].a, g1.edges[i - 1].b), std::tie(e1.a, e1.b));
    }
  }
}

// The final graph's edges are built on every thread in slices cut between pairs; with
// pending merges (several stored edges onto one pair, summed) they equal a single pass's.
TEST(GraphAccumulatorEdges, ThreadsGiveTheGraphOfOnePass) {
  // Every fifth label merged into a smaller one, some through chains.
  std::mt19937 rng(5);
  std::vector<int32_t> parent(401);
  for (int32_t l = 1; l <= 400; ++l) {
    parent[l] = l > 1 && l % 5 == 0 ? static_cast<int32_t>(rng() % (l - 1)) + 1 : l;
  }
  expectThreadsGiveOnePass([&](int32_t l) { return parent[l]; }, 4000);
  // Everything merged into 16 super-points: runs of 50 stored edges per pair, so a slice cut
  // by position alone would split one.
  expectThreadsGiveOnePass([](int32_t l) { return l <= 16 ? l : (l % 16) + 1; }, 100);
}

}  // namespace
}  // namespace panmap
