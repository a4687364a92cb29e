#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "panmap/map/internal/vote_rows.h"
#include "panmap/map/voxel.h"

namespace panmap {
namespace internal {
namespace {

TsdfMap::Config voxelSize(float size_m) {
  TsdfMap::Config config;
  config.voxel_size_m = size_m;
  return config;
}

// One row, identity pose, fx = 8 and cx = cy = 0: pixel u at depth 1 is the point (u / 8, 0, 1),
// so with 0.5 m voxels pixels 0-3 share voxel (0, 0, 2) and pixels 4-7 voxel (1, 0, 2).
TEST(VoteRows, RunsOfOneRowByHand) {
  TsdfMap map(voxelSize(0.5f));
  Block* block = map.allocateBlock(BlockIndex(0, 0, 0));  // voxels x 0-7, i.e. pixels 0-31
  const int w = 48;
  Image<float> depth(w, 1, 1.0f);
  LabelImage labels(w, 1, 0);
  const int32_t label_of[] = {1, 1, 2, 2, 3, 3, 3, 3, 0, 7, 7, 7};
  for (int u = 0; u < 12; ++u) labels(u, 0) = label_of[u];
  depth(10, 0) = 0.0f;  // no depth: no vote, and it does not split the run of 7s
  labels(40, 0) = 5;    // its block is not allocated: no vote
  labels(13, 0) = -2;   // not a super-point: no vote
  const RowCamera cam{8.0f, 8.0f, 0.0f, 0.0f};
  for (const bool vector_path : {false, true}) {
    MutableVoxelLookup lookup(map);
    std::vector<VoteRun> runs(w);
    const size_t n = vector_path
                         ? findRowVotes(depth, labels, 0, 1, Eigen::Isometry3f::Identity(), cam,
                                        &lookup, runs.data())
                         : findRowVotesScalar(depth, labels, 0, 1, Eigen::Isometry3f::Identity(),
                                              cam, &lookup, runs.data());
    ASSERT_EQ(n, 4u) << (vector_path ? "vector" : "scalar");
    EXPECT_EQ(runs[0].block, block);
    EXPECT_EQ(runs[0].voxel, Block::linear(0, 0, 2));
    EXPECT_EQ(runs[0].label, 1);
    EXPECT_EQ(runs[0].count, 2u);
    EXPECT_EQ(runs[1].block, block);
    EXPECT_EQ(runs[1].voxel, Block::linear(0, 0, 2));
    EXPECT_EQ(runs[1].label, 2);
    EXPECT_EQ(runs[1].count, 2u);
    EXPECT_EQ(runs[2].block, block);
    EXPECT_EQ(runs[2].voxel, Block::linear(1, 0, 2));
    EXPECT_EQ(runs[2].label, 3);
    EXPECT_EQ(runs[2].count, 4u);
    EXPECT_EQ(runs[3].block, block);
    EXPECT_EQ(runs[3].voxel, Block::linear(2, 0, 2));  // pixels 9 and 11
    EXPECT_EQ(runs[3].label, 7);
    EXPECT_EQ(runs[3].count, 2u);
  }
  // Every second pixel: 0, 2 | 4, 6 | 8 (no label) | 10 (no depth).
  MutableVoxelLookup lookup(map);
  std::vector<VoteRun> runs(w);
  const size_t n =
      findRowVotes(depth, labels, 0, 2, Eigen::Isometry3f::Identity(), cam, &lookup, runs.data());
  ASSERT_EQ(n, 3u);
  EXPECT_EQ(runs[0].label, 1);
  EXPECT_EQ(runs[0].count, 1u);
  EXPECT_EQ(runs[1].label, 2);
  EXPECT_EQ(runs[1].count, 1u);
  EXPECT_EQ(runs[2].label, 3);
  EXPECT_EQ(runs[2].count, 2u);
}

// The 8-wide path must find the portable path's voxels and runs exactly, for random poses,
// rows that are not a multiple of 8 wide, holes, label changes and unallocated blocks.
TEST(VoteRows, VectorPathMatchesScalarExactly) {
  if (!voteRowsUseAvx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const int w = 203;
  const RowCamera cam{180.0f, 182.5f, 101.3f, 15.7f};
  size_t runs_compared = 0, votes_compared = 0, long_runs = 0;
  for (int trial = 0; trial < 60; ++trial) {
    // The last 40 trials: 5 mm voxels 60 m from the origin, where a different rounding of
    // RowGrid's sums (an ulp there is 4 um) moves some points to a neighbouring voxel.
    const bool far = trial >= 20;
    // Every fourth of the first 20: 25 cm voxels over smooth depth with long label runs, where
    // most groups of eight pixels vote for one voxel (the vector path's shortcut).
    const bool coarse = !far && trial % 4 == 3;
    const int h = far ? 3 : 31;
    TsdfMap map(voxelSize(far ? 0.005f : coarse ? 0.25f : (trial % 2 ? 0.01f : 0.037f)));
    Eigen::Isometry3f T_W_C = Eigen::Isometry3f::Identity();
    T_W_C.linear() =
        Eigen::AngleAxisf(3.0f * unit(rng),
                          Eigen::Vector3f(unit(rng), unit(rng), unit(rng)).normalized())
            .toRotationMatrix();
    T_W_C.translation() = Eigen::Vector3f(unit(rng), unit(rng), unit(rng)) * (far ? 60.0f : 2.0f);
    Image<float> depth(w, h);
    LabelImage labels(w, h);
    int32_t label = 1;
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        const float noise = coarse ? 0.0f : 0.3f * unit(rng) * unit(rng);
        depth(u, v) = rng() % (coarse ? 401 : 23) == 0 ? 0.0f : 1.2f + 0.004f * u + noise;
        if (rng() % (coarse ? 97 : 17) == 0) {
          label = static_cast<int32_t>(rng() % 9) - 1;  // some 0 and -1
        }
        labels(u, v) = label;
      }
    }
    // Allocate about 3/4 of the blocks the points fall in (all of them far out).
    const float inv_block = 1.0f / map.blockSize();
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        const float d = depth(u, v);
        const Eigen::Vector3f p =
            T_W_C * Eigen::Vector3f((u - cam.cx) * d / cam.fx, (v - cam.cy) * d / cam.fy, d);
        const BlockIndex b((p * inv_block).array().floor().cast<int>());
        if (far || (b.x() * 7 + b.y() * 13 + b.z() * 5) % 4 != 0) map.allocateBlock(b);
      }
    }
    for (int v = 0; v < h; ++v) {
      MutableVoxelLookup lookup_a(map), lookup_b(map);
      std::vector<VoteRun> a(w), b(w);
      const size_t na = findRowVotes(depth, labels, v, 1, T_W_C, cam, &lookup_a, a.data());
      const size_t nb = findRowVotesScalar(depth, labels, v, 1, T_W_C, cam, &lookup_b, b.data());
      ASSERT_EQ(na, nb) << "trial " << trial << " row " << v;
      for (size_t i = 0; i < na; ++i) {
        ASSERT_EQ(a[i].block, b[i].block) << "trial " << trial << " row " << v << " run " << i;
        ASSERT_EQ(a[i].voxel, b[i].voxel) << "trial " << trial << " row " << v << " run " << i;
        ASSERT_EQ(a[i].label, b[i].label);
        ASSERT_EQ(a[i].count, b[i].count);
        votes_compared += a[i].count;
        if (coarse) long_runs += a[i].count >= 16;
      }
      runs_compared += na;
    }
  }
  EXPECT_GT(runs_compared, 10000u);  // the comparison must not be vacuous
  EXPECT_GT(votes_compared, runs_compared);
  EXPECT_GT(long_runs, 200u);
}

// n votes at once must leave the voxel exactly as n single votes do: slot filling, eviction
// of the weakest and saturation.
TEST(VoteRows, AddVotesEqualsRepeatedAddVote) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 500; ++trial) {
    VoxelVotes bulk, single;
    bool evicted_bulk = false, evicted_single = false;
    for (int step = 0; step < 30; ++step) {
      const int32_t label = 1 + static_cast<int32_t>(rng() % 7);
      const uint32_t n = 1 + rng() % 5;
      evicted_bulk |= addVotes(&bulk, label, n);
      for (uint32_t i = 0; i < n; ++i) evicted_single |= addVote(&single, label);
      for (int s = 0; s < kVoteSlots; ++s) {
        ASSERT_EQ(bulk.slots[s].label, single.slots[s].label) << "trial " << trial;
        ASSERT_EQ(bulk.slots[s].count, single.slots[s].count) << "trial " << trial;
      }
    }
    EXPECT_EQ(evicted_bulk, evicted_single);
  }
  // A slot about to overflow halves the voxel's counts (rounding up) and then takes the votes:
  // the ratios Eq. 2 reads survive, and no slot empties.
  VoxelVotes full;
  full.slots[0] = LabelVote{3, kMaxVoteCount - 2};
  full.slots[1] = LabelVote{5, 40001};
  full.slots[2] = LabelVote{6, 1};
  addVotes(&full, 3, 10);
  EXPECT_EQ(full.slots[0].count, 32767u + 10u);
  EXPECT_EQ(full.slots[1].count, 20001u);
  EXPECT_EQ(full.slots[2].count, 1u);
  EXPECT_EQ(argmaxLabel(full, [](int32_t l) { return l; }), 3);
  // A new slot takes at most the cap, however many votes arrive at once.
  addVotes(&full, 4, 100000);
  EXPECT_EQ(full.slots[3].label, 4);
  EXPECT_EQ(full.slots[3].count, kMaxVoteCount);
}

// The lookups' floor must agree with std::floor everywhere a voxel index can be.
// A band's runs summed by hand: each voxel and label once, at the place of its first run.
TEST(VoteSums, EachVoxelAndLabelOnceWhereFirstSeen) {
  TsdfMap map(voxelSize(0.1f));
  Block* a = map.allocateBlock(BlockIndex(0, 0, 0));
  Block* b = map.allocateBlock(BlockIndex(1, 0, 0));
  std::vector<VoteRun> runs = {{a, 5, 7, 2}, {a, 6, 7, 1}, {b, 5, 7, 4}, {a, 5, 9, 1},
                               {a, 5, 7, 3}, {b, 5, 7, 1}, {a, 6, 7, 10}};
  VoteSumTable table;
  const size_t n = sumVoteRuns(runs.data(), runs.size(), &table);
  ASSERT_EQ(n, 4u);
  const VoteRun want[] = {{a, 5, 7, 5}, {a, 6, 7, 11}, {b, 5, 7, 5}, {a, 5, 9, 1}};
  for (size_t i = 0; i < n; ++i) {
    EXPECT_EQ(runs[i].block, want[i].block) << i;
    EXPECT_EQ(runs[i].voxel, want[i].voxel) << i;
    EXPECT_EQ(runs[i].label, want[i].label) << i;
    EXPECT_EQ(runs[i].count, want[i].count) << i;
  }
}

// The table is reused from band to band without clearing: a sum of the band before must not be
// found again (here it would add the run to itself), also when the band stamp wraps around to
// the stamp the slot was written with.
TEST(VoteSums, ABandSeesNoSumOfTheBandBefore) {
  TsdfMap map(voxelSize(0.1f));
  Block* a = map.allocateBlock(BlockIndex(0, 0, 0));
  VoteSumTable table;
  auto sumOne = [&] {
    VoteRun run{a, 3, 4, 3};
    EXPECT_EQ(sumVoteRuns(&run, 1, &table), 1u);
    return run.count;
  };
  for (int band = 0; band < 3; ++band) EXPECT_EQ(sumOne(), 3u) << "band " << band;
  table.band = 0;
  EXPECT_EQ(sumOne(), 3u);  // written with stamp 1
  table.band = 0xFFFFFFFFu;
  EXPECT_EQ(sumOne(), 3u);  // the stamp wraps to 1 again
}

// Many pairs, as at 1 cm where a band's voxels are many: each is left once, with its total, in
// the order the pairs first appeared, whatever the table held before (a smaller band first).
TEST(VoteSums, ManyPairsAreEachSummedOnceInTheOrderFirstSeen) {
  TsdfMap map(voxelSize(0.1f));
  std::vector<Block*> blocks;
  for (int x = 0; x < 8; ++x) blocks.push_back(map.allocateBlock(BlockIndex(x, 0, 0)));
  std::mt19937 rng(5);
  VoteSumTable table;
  for (const int size : {10, 20000}) {
    std::vector<VoteRun> runs;
    for (int i = 0; i < size; ++i) {
      runs.push_back(VoteRun{blocks[rng() % blocks.size()], static_cast<int32_t>(rng() % 512),
                             static_cast<int32_t>(1 + rng() % 3), 1 + rng() % 5});
    }
    using Pair = std::tuple<Block*, int32_t, int32_t>;
    auto totals = [](const VoteRun* r, size_t n, std::vector<Pair>* order) {
      std::map<Pair, uint64_t> sum;
      for (size_t i = 0; i < n; ++i) {
        const Pair pair{r[i].block, r[i].voxel, r[i].label};
        if (sum.count(pair) == 0) order->push_back(pair);
        sum[pair] += r[i].count;
      }
      return sum;
    };
    std::vector<Pair> order_before, order_after;
    const auto before = totals(runs.data(), runs.size(), &order_before);
    const size_t n = sumVoteRuns(runs.data(), runs.size(), &table);
    const auto after = totals(runs.data(), n, &order_after);
    EXPECT_EQ(after, before) << size;
    EXPECT_EQ(order_after, order_before) << size;
    EXPECT_EQ(n, before.size()) << size;  // each pair once
  }
}

TEST(VoxelLookup, FloorToIntMatchesStdFloor) {
  const float edges[] = {0.0f,        -0.0f,       1.0f,         -1.0f,  0.5f,   -0.5f,
                         -1e-30f,     1e-30f,      -0.99999994f, 2.5f,   -2.5f,  8388607.5f,
                         -8388607.5f, 16777217.0f, -16777216.0f, 2.0e9f, -2.0e9f};
  for (float x : edges) {
    EXPECT_EQ(MutableVoxelLookup::floorToInt(x), static_cast<int>(std::floor(x))) << x;
  }
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> wide(-1e6f, 1e6f), narrow(-3.0f, 3.0f);
  for (int i = 0; i < 200000; ++i) {
    const float x = i % 2 ? wide(rng) : narrow(rng);
    ASSERT_EQ(MutableVoxelLookup::floorToInt(x), static_cast<int>(std::floor(x))) << x;
  }
}

}  // namespace
}  // namespace internal
}  // namespace panmap
