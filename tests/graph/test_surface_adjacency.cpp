#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/graph/graph_accumulator.h"
#include "panmap/graph/surface_adjacency.h"
#include "panmap/superpoint/label_registry.h"

namespace panmap {
namespace {

// A map of hand-set voxels at 0.1 m: each voxel observed with the given sdf (voxels) and one
// vote for a label.
class HandMap {
 public:
  HandMap() : map_(config()) {}
  static TsdfMap::Config config() {
    TsdfMap::Config c;
    c.voxel_size_m = 0.1f;
    return c;
  }
  // Global voxel coordinates (any sign); sdf in voxels.
  void set(int gx, int gy, int gz, int32_t label, float sdf_voxels = 0.0f, float weight = 1.0f) {
    auto split = [](int g, int* local) {
      const int b = g >= 0 ? g / kBlockSide : -((-g + kBlockSide - 1) / kBlockSide);
      *local = g - b * kBlockSide;
      return b;
    };
    int x, y, z;
    const BlockIndex index(split(gx, &x), split(gy, &y), split(gz, &z));
    Block* block = map_.allocateBlock(index);
    Voxel& v = block->at(x, y, z);
    v.sdf_m = sdf_voxels * 0.1f;
    v.weight = weight;
    block->votesToWrite(Block::linear(x, y, z))->slots[0] = LabelVote{label, 1};
  }
  const TsdfMap& map() const { return map_; }

 private:
  TsdfMap map_;
};

int32_t identity(int32_t l) { return l; }

TEST(SurfaceAdjacency, TotalsCountEveryVoxelAndATableResolvesAsTheFunctionDoes) {
  HandMap m;
  m.set(0, 0, 0, 1);
  m.set(1, 0, 0, 3);              // label 3 was merged into 1
  m.set(-1, 2, 0, 2);             // another block (negative x)
  m.set(7, 0, 0, 2, 2.5f);        // off the band: counted in the totals, not on the surface
  m.set(5, 0, 0, 2, 0.0f, 0.0f);  // never observed but voted: counted too
  const std::vector<int32_t> roots = {0, 1, 2, 1};
  SurfaceAdjacency::OwnerTotals totals;
  totals.voxels.assign(4, 0);
  totals.centre_sum.assign(4, Eigen::Vector3d::Zero());
  const SurfaceAdjacency s = SurfaceAdjacency::compute(m.map(), roots, 2.0f, &totals);
  EXPECT_EQ(totals.voxels, (std::vector<int>{0, 2, 3, 0}));
  // Voxel centres at 0.1 m: (i + 0.5) * 0.1.
  EXPECT_NEAR(totals.centre_sum[1].x(), 0.05 + 0.15, 1e-6);
  EXPECT_NEAR(totals.centre_sum[2].x(), -0.05 + 0.75 + 0.55, 1e-6);
  EXPECT_NEAR(totals.centre_sum[2].y(), 0.25 + 0.05 + 0.05, 1e-6);
  EXPECT_EQ(s.surfaceVoxels(1), 2);
  EXPECT_EQ(s.surfaceVoxels(2), 1);
  EXPECT_EQ(s.surfaceVoxels(3), 0);
  EXPECT_TRUE(s.touching(1, 2) == false);
  const SurfaceAdjacency f = SurfaceAdjacency::compute(
      m.map(), [&roots](int32_t l) { return l > 0 && l < 4 ? roots[l] : 0; }, 2.0f);
  EXPECT_EQ(f.numOwners(), s.numOwners());
  EXPECT_EQ(f.numPairs(), s.numPairs());
  // Sizes that disagree are refused.
  totals.centre_sum.pop_back();
  EXPECT_THROW(SurfaceAdjacency::compute(m.map(), roots, 2.0f, &totals), Error);
}

TEST(SurfaceAdjacency, OwnersAndTouchingPairsOnHandSetVoxels) {
  HandMap m;
  m.set(0, 0, 0, 1);
  m.set(1, 0, 0, 1);
  m.set(2, 0, 0, 2);              // face neighbour of a voxel of 1
  m.set(3, 1, 1, 3);              // corner (26-) neighbour of 2's voxel
  m.set(6, 0, 0, 4);              // alone
  m.set(7, 0, 0, 5, 2.5f);        // next to 4 but off the 2-voxel band: not surface
  m.set(5, 0, 0, 6, 0.0f, 0.0f);  // next to 4 but never observed
  const SurfaceAdjacency s = SurfaceAdjacency::compute(m.map(), identity, 2.0f);
  EXPECT_EQ(s.surfaceVoxels(1), 2);
  EXPECT_EQ(s.surfaceVoxels(2), 1);
  EXPECT_EQ(s.surfaceVoxels(3), 1);
  EXPECT_EQ(s.surfaceVoxels(4), 1);
  EXPECT_EQ(s.surfaceVoxels(5), 0);
  EXPECT_EQ(s.surfaceVoxels(6), 0);
  EXPECT_EQ(s.numOwners(), 4u);
  EXPECT_TRUE(s.touching(1, 2));
  EXPECT_TRUE(s.touching(2, 1));
  EXPECT_TRUE(s.touching(2, 3));
  EXPECT_FALSE(s.touching(1, 3));  // two voxels apart
  EXPECT_FALSE(s.touching(4, 5));
  EXPECT_FALSE(s.touching(4, 6));
  EXPECT_FALSE(s.touching(1, 1));
  EXPECT_EQ(s.numPairs(), 2u);
}

TEST(SurfaceAdjacency, TouchingAcrossBlockBordersInEveryDirection) {
  // Voxel 7 and voxel 8 lie in different blocks along each axis, and diagonally.
  const int offsets[][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, -1, 0}, {1, 1, -1}, {-1, 1, 1}};
  for (const auto& d : offsets) {
    HandMap m;
    m.set(7, 7, 7, 1);
    m.set(7 + d[0] * 1, 7 + d[1] * 1, 7 + d[2] * 1, 2);
    m.set(-1, -1, -1, 3);
    m.set(0, 0, 0, 4);  // across the origin: negative block indices
    const SurfaceAdjacency s = SurfaceAdjacency::compute(m.map(), identity, 2.0f);
    EXPECT_TRUE(s.touching(1, 2)) << d[0] << " " << d[1] << " " << d[2];
    EXPECT_TRUE(s.touching(3, 4));
    EXPECT_FALSE(s.touching(1, 4));
  }
}

TEST(SurfaceAdjacency, LabelsResolveToTheirRoots) {
  HandMap m;
  m.set(0, 0, 0, 1);
  m.set(1, 0, 0, 2);
  m.set(2, 0, 0, 3);
  // 2 was merged into 1: one owner of two voxels, touching 3 only.
  const SurfaceAdjacency s = SurfaceAdjacency::compute(
      m.map(), [](int32_t l) { return l == 2 ? 1 : l; }, 2.0f);
  EXPECT_EQ(s.surfaceVoxels(1), 2);
  EXPECT_EQ(s.surfaceVoxels(2), 0);
  EXPECT_TRUE(s.touching(1, 3));
  EXPECT_EQ(s.numPairs(), 1u);
  EXPECT_THROW(SurfaceAdjacency::compute(m.map(), identity, 0.0f), Error);
}

// Scanned by two threads or one, the map gives the same owners, pairs and totals: each
// thread's counts and voxel index sums are exact, so how the blocks were shared out does not
// show. 300 blocks of random labels, some off the band.
TEST(SurfaceAdjacency, TwoThreadsFindWhatOneFinds) {
  HandMap m;
  uint32_t state = 12345;
  auto next = [&state] { return state = state * 1664525u + 1013904223u; };
  for (int i = 0; i < 20000; ++i) {
    const int x = static_cast<int>(next() >> 20) % 80 - 40;
    const int y = static_cast<int>(next() >> 20) % 40 - 20;
    const int z = static_cast<int>(next() >> 20) % 30;
    m.set(x, y, z, 1 + static_cast<int32_t>(next() >> 24) % 50, (next() >> 31) ? 0.0f : 3.0f);
  }
  ASSERT_GT(m.map().numBlocks(), 200u);
  auto totalsFor = [] {
    SurfaceAdjacency::OwnerTotals t;
    t.voxels.assign(52, 0);
    t.centre_sum.assign(52, Eigen::Vector3d::Zero());
    return t;
  };
  SurfaceAdjacency::OwnerTotals one = totalsFor(), two = totalsFor();
  const SurfaceAdjacency a = SurfaceAdjacency::compute(m.map(), identity, 2.0f, &one);
  ThreadPool pool(2);
  const SurfaceAdjacency b = SurfaceAdjacency::compute(m.map(), identity, 2.0f, &two, &pool);
  EXPECT_EQ(a.numOwners(), b.numOwners());
  EXPECT_EQ(a.numPairs(), b.numPairs());
  EXPECT_GT(a.numPairs(), 1000u);
  for (int32_t l = 1; l <= 50; ++l) {
    EXPECT_EQ(a.surfaceVoxels(l), b.surfaceVoxels(l));
    for (int32_t k = 1; k <= 50; ++k) EXPECT_EQ(a.touching(l, k), b.touching(l, k));
  }
  EXPECT_EQ(one.voxels, two.voxels);
  EXPECT_EQ(one.centre_sum, two.centre_sum);  // exactly
  int voxels = 0;
  for (int v : one.voxels) voxels += v;
  int distinct = 0;  // every set voxel counts once, however often it was drawn
  for (const auto& block : m.map().blocks()) {
    for (const VoxelVotes& v : block->vote_sets) distinct += v.slots[0].count > 0;
  }
  EXPECT_EQ(voxels, distinct);
}

// Pruning keeps touching pairs and strong pairs between surface owners, drops the rest.
TEST(GraphPruning, KeepsTouchingAndStrongPairsOfSurfaceOwners) {
  HandMap m;
  m.set(0, 0, 0, 1);
  m.set(1, 0, 0, 2);  // touches 1
  m.set(5, 0, 0, 3);  // apart from both
  m.set(9, 0, 0, 4);  // apart
  // 5 owns no surface (only a voxel far behind it).
  m.set(12, 0, 0, 5, 3.0f);
  const SurfaceAdjacency surface = SurfaceAdjacency::compute(m.map(), identity, 2.0f);

  GraphConfig config;  // edge_min_share 0.1
  GraphAccumulator graph{config};
  GraphAccumulator::Snapshot s;
  s.scores[1][5] = 10.0;
  s.scores[2][5] = 10.0;
  s.scores[3][5] = 4.0;
  s.scores[4][5] = 20.0;
  s.scores[5][5] = 50.0;
  s.edges[{1, 2}][5] = 0.01;  // weak, but touching: kept
  s.edges[{1, 3}][5] = 0.4;   // 0.4 >= 0.1 x min(10, 4): kept
  s.edges[{1, 4}][5] = 0.9;   // 0.9 < 0.1 x min(10, 20): dropped
  s.edges[{1, 4}][0] = 5.0;   // P_apart alone never makes a pair strong
  s.edges[{3, 4}][-5] = 0.5;  // P_sep 0.5 >= 0.1 x 4: kept
  s.edges[{1, 5}][5] = 40.0;  // 5 owns no surface: dropped
  graph.restore(s);
  LabelRegistry registry;
  for (int i = 0; i < 5; ++i) registry.create();
  EXPECT_EQ(graph.pruneEdges(surface, registry), 2u);
  const GraphAccumulator::Snapshot after = graph.snapshot();
  ASSERT_EQ(after.edges.size(), 3u);
  EXPECT_EQ(after.edges.count({1, 2}), 1u);
  EXPECT_EQ(after.edges.count({1, 3}), 1u);
  EXPECT_EQ(after.edges.count({3, 4}), 1u);
  EXPECT_EQ(after.scores.size(), 5u);  // scores stay: only edges go

  // The threshold is inclusive, and pruning off keeps everything.
  GraphConfig off;
  off.prune_edges = false;
  GraphAccumulator kept{off};
  kept.restore(s);
  EXPECT_EQ(kept.pruneEdges(surface, registry), 0u);
  EXPECT_EQ(kept.snapshot().edges.size(), 5u);
  EXPECT_TRUE(graph.keepEdge(1, 3, 0.4, surface));
  EXPECT_FALSE(graph.keepEdge(1, 3, 0.39, surface));
  EXPECT_FALSE(graph.keepEdge(1, 1, 100.0, surface));
}

TEST(GraphPruning, RejectsBadConfig) {
  GraphConfig bad;
  bad.edge_min_share = 1.5;
  EXPECT_THROW(GraphAccumulator{bad}, Error);
  bad.edge_min_share = 0.1;
  bad.surface_band_voxels = 0.0f;
  EXPECT_THROW(GraphAccumulator{bad}, Error);
}

}  // namespace
}  // namespace panmap
