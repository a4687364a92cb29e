#include <gtest/gtest.h>

#include <vector>

#include "panmap/core/error.h"
#include "panmap/core/thread_pool.h"
#include "panmap/graph/surface_adjacency.h"
#include "panmap/graph/surface_scan.h"
#include "panmap/map/voxel_lookup.h"
#include "panmap/superpoint/label_registry.h"

namespace panmap {
namespace {

constexpr int32_t kLabels = 60;

TsdfMap::Config config() {
  TsdfMap::Config c;
  c.voxel_size_m = 0.1f;
  return c;
}

// Random voxel writes through a MutableVoxelLookup (so the blocks are stamped as every writer
// of the mapper stamps them), in a box of about 10 x 6 x 4 blocks.
// The votes of the voxel `lookup` found last, given empty slots when it had none.
VoxelVotes* votesOf(const MutableVoxelLookup& lookup, const Voxel* voxel) {
  Block* block = lookup.lastBlock();
  return block->votesToWrite(block->indexOf(*voxel));
}

class RandomWriter {
 public:
  explicit RandomWriter(uint32_t seed) : state_(seed) {}
  uint32_t next() { return state_ = state_ * 1664525u + 1013904223u; }
  int below(int n) { return static_cast<int>((next() >> 8) % static_cast<uint32_t>(n)); }

  // n voxels within `span` voxels of (cx, cy, cz): observed or not, in the band or not, with
  // one to three votes (labels may be ones merged away since).
  void write(TsdfMap* map, int n, int cx, int cy, int cz, int span) {
    for (int i = 0; i < n; ++i) {
      const int gx = cx + below(2 * span + 1) - span, gy = cy + below(2 * span + 1) - span;
      const int gz = cz + below(2 * span + 1) - span;
      map->allocateBlock(BlockIndex(gx >> 3, gy >> 3, gz >> 3));
      MutableVoxelLookup lookup(*map);
      Voxel* v = lookup.findGrid(gx, gy, gz);
      VoxelVotes* v_votes = votesOf(lookup, v);
      ASSERT_NE(v, nullptr);
      v->weight = below(5) == 0 ? 0.0f : 1.0f;
      v->sdf_m = below(3) == 0 ? 0.35f : 0.05f;  // 3.5 voxels: off a 2-voxel band
      const int votes = 1 + below(3);
      for (int k = 0; k < kVoteSlots; ++k) v_votes->slots[k] = LabelVote{};
      for (int k = 0; k < votes; ++k) {
        v_votes->slots[k] = LabelVote{1 + below(kLabels), static_cast<uint16_t>(1 + below(4))};
      }
    }
  }

 private:
  uint32_t state_;
};

// What a full scan of the map finds, for comparison.
struct Full {
  SurfaceAdjacency adjacency;
  SurfaceAdjacency::OwnerTotals totals;
  std::vector<uint8_t> has_votes;
};

Full fullScan(const TsdfMap& map, const LabelRegistry& registry) {
  registry.flatten();
  Full f;
  f.totals.voxels.assign(kLabels + 1, 0);
  f.totals.centre_sum.assign(kLabels + 1, Eigen::Vector3d::Zero());
  f.adjacency = SurfaceAdjacency::compute(map, registry.parents(), 2.0f, &f.totals);
  f.has_votes.assign(static_cast<size_t>(registry.size()) + 1, 0);
  for (const auto& block : map.blocks()) {
    for (const VoxelVotes& votes : block->vote_sets) {
      for (const LabelVote& vote : votes) {
        if (vote.count > 0) f.has_votes[static_cast<size_t>(registry.resolve(vote.label))] = 1;
      }
    }
  }
  return f;
}

void expectSame(const SurfaceScan& scan, const TsdfMap& map, const LabelRegistry& registry) {
  const Full full = fullScan(map, registry);
  const SurfaceAdjacency a = scan.adjacency();
  ASSERT_EQ(a.numOwners(), full.adjacency.numOwners());
  ASSERT_EQ(a.numPairs(), full.adjacency.numPairs());
  for (int32_t l = 1; l <= kLabels; ++l) {
    ASSERT_EQ(a.surfaceVoxels(l), full.adjacency.surfaceVoxels(l)) << l;
    for (int32_t k = l + 1; k <= kLabels; ++k) {
      ASSERT_EQ(a.touching(l, k), full.adjacency.touching(l, k)) << l << " " << k;
    }
  }
  SurfaceAdjacency::OwnerTotals totals;
  totals.voxels.assign(kLabels + 1, 0);
  totals.centre_sum.assign(kLabels + 1, Eigen::Vector3d::Zero());
  scan.addTotals(&totals);
  EXPECT_EQ(totals.voxels, full.totals.voxels);
  EXPECT_EQ(totals.centre_sum, full.totals.centre_sum);  // bit for bit
  EXPECT_EQ(scan.hasVotes(), full.has_votes);
}

// Rounds of local writes and merges, each followed by a refresh: the results always equal a
// full scan's, while a refresh after a local change reads a small part of the map.
TEST(SurfaceScan, RefreshedAfterWritesAndMergesItEqualsAFullScan) {
  for (const int threads : {1, 2}) {
    TsdfMap map(config());
    LabelRegistry registry;
    for (int i = 0; i < kLabels; ++i) registry.create();
    RandomWriter rng(7);
    ThreadPool pool(threads);
    rng.write(&map, 6000, 0, 0, 0, 40);
    SurfaceScan scan;
    scan.refresh(map, registry, 2.0f, &pool);
    EXPECT_EQ(scan.blocksRead(), map.numBlocks());
    expectSame(scan, map, registry);
    size_t fewest = map.numBlocks();
    for (int round = 0; round < 12; ++round) {
      // A few voxels near one spot (sometimes none), sometimes a merge.
      if (round % 3 != 2) {
        rng.write(&map, 1 + rng.below(20), rng.below(48) - 24, rng.below(48) - 24,
                  rng.below(48) - 24, 3);
      }
      if (round % 2 == 1) registry.merge(1 + rng.below(kLabels), 1 + rng.below(kLabels));
      scan.refresh(map, registry, 2.0f, &pool);
      SCOPED_TRACE(testing::Message() << "threads " << threads << " round " << round);
      expectSame(scan, map, registry);
      if (round % 2 == 0) fewest = std::min(fewest, scan.blocksRead());
    }
    // A local write re-reads its block and the 26 around it, not the map.
    EXPECT_LE(fewest, 27u * 8u);
    EXPECT_LT(fewest * 4, map.numBlocks());
    // Nothing changed: nothing read.
    scan.refresh(map, registry, 2.0f, &pool);
    EXPECT_EQ(scan.blocksRead(), 0u);
  }
}

// Voxels of one label per 2 x 2 x 2 blocks (one vote each, so no voxel has a tie): a merge
// only renames, and the refresh renames the summaries of the merged labels' blocks and their
// neighbours without reading a block, with the results of a full scan. A voxel with two roots
// tied for its argmax sends its block back to be read, and so do two roots of one block
// becoming one.
TEST(SurfaceScan, MergesThatOnlyRenameReadNoBlock) {
  for (const int threads : {1, 2}) {
    SCOPED_TRACE(testing::Message() << "threads " << threads);
    TsdfMap map(config());
    LabelRegistry registry;
    for (int i = 0; i < kLabels; ++i) registry.create();
    ThreadPool pool(threads);
    RandomWriter rng(5);
    auto regionLabel = [](int gx, int gy, int gz) {
      const int rx = (gx >> 4) + 3, ry = (gy >> 4) + 3, rz = (gz >> 4) + 3;
      return 1 + (rx + 6 * ry + 36 * rz) % kLabels;
    };
    for (int i = 0; i < 8000; ++i) {
      const int gx = rng.below(81) - 40, gy = rng.below(81) - 40, gz = rng.below(81) - 40;
      map.allocateBlock(BlockIndex(gx >> 3, gy >> 3, gz >> 3));
      MutableVoxelLookup lookup(map);
      Voxel* v = lookup.findGrid(gx, gy, gz);
      VoxelVotes* v_votes = votesOf(lookup, v);
      v->weight = rng.below(5) == 0 ? 0.0f : 1.0f;
      v->sdf_m = rng.below(3) == 0 ? 0.35f : 0.05f;
      v_votes->slots[0] =
          LabelVote{regionLabel(gx, gy, gz), static_cast<uint16_t>(1 + rng.below(4))};
    }
    SurfaceScan scan;
    // Brings the scan up to date and compares it with a full scan.
    auto refreshAndCompare = [&] {
      scan.refresh(map, registry, 2.0f, &pool);
      expectSame(scan, map, registry);
    };
    refreshAndCompare();
    // Neighbouring regions' labels (touching pairs become one super-point) and distant ones.
    for (const auto& [a, b] : {std::make_pair(regionLabel(0, 0, 0), regionLabel(16, 0, 0)),
                               std::make_pair(regionLabel(-40, -40, -40), regionLabel(0, 16, 0)),
                               std::make_pair(regionLabel(0, 0, 16), regionLabel(16, 0, 0))}) {
      registry.merge(a, b);
      SCOPED_TRACE(testing::Message() << "merged " << a << " and " << b);
      refreshAndCompare();
      EXPECT_EQ(scan.blocksRead(), 0u);
      EXPECT_GT(scan.blocksRenamed(), 0u);
    }
    // A tie in one voxel of a block of region (1, 1, 1), beside a voxel of a third label: a
    // merge of the third label renames the block, a merge of a tied label reads it.
    const int32_t tied = regionLabel(20, 20, 20), rival = regionLabel(-40, 0, 0);
    const int32_t third = regionLabel(-40, -40, 0), survivor = regionLabel(-40, -40, -40);
    ASSERT_LT(survivor, third);  // the smaller root survives a merge
    // Merged into a label below its rival's, the tied label wins the tie it lost.
    const int32_t below_rival = regionLabel(-20, -40, -40);
    ASSERT_LT(below_rival, rival);
    ASSERT_LT(rival, tied);
    {
      MutableVoxelLookup lookup(map);
      Voxel* v = lookup.findGrid(20, 20, 20);
      VoxelVotes* v_votes = votesOf(lookup, v);
      v->weight = 1.0f;
      v->sdf_m = 0.0f;
      v_votes->slots[0] = LabelVote{tied, 3};
      v_votes->slots[1] = LabelVote{rival, 3};
      Voxel* w = lookup.findGrid(21, 20, 20);
      VoxelVotes* w_votes = votesOf(lookup, w);
      w->weight = 1.0f;
      w->sdf_m = 0.0f;
      w_votes->slots[0] = LabelVote{third, 2};
      for (int k = 1; k < kVoteSlots; ++k) w_votes->slots[k] = LabelVote{};
    }
    refreshAndCompare();
    registry.merge(third, survivor);
    refreshAndCompare();
    EXPECT_EQ(scan.blocksRead(), 0u);
    EXPECT_GT(scan.blocksRenamed(), 0u);
    registry.merge(tied, below_rival);
    refreshAndCompare();
    EXPECT_GT(scan.blocksRead(), 0u);
    // The two roots of that voxel become one: read again, their votes summed.
    registry.merge(rival, tied);
    refreshAndCompare();
    EXPECT_GT(scan.blocksRead(), 0u);
    // No tie, 3 against 2 and 2, until the two 2s become one super-point of 4 and win.
    const int32_t own = regionLabel(-20, -20, -20);
    const int32_t p = regionLabel(-40, 40, 0), q = regionLabel(40, -40, 0);
    ASSERT_NE(registry.resolve(p), registry.resolve(q));
    ASSERT_NE(registry.resolve(own), registry.resolve(p));
    ASSERT_NE(registry.resolve(own), registry.resolve(q));
    {
      MutableVoxelLookup lookup(map);
      Voxel* v = lookup.findGrid(-20, -20, -20);
      VoxelVotes* v_votes = votesOf(lookup, v);
      v->weight = 1.0f;
      v->sdf_m = 0.0f;
      v_votes->slots[0] = LabelVote{own, 3};
      v_votes->slots[1] = LabelVote{p, 2};
      v_votes->slots[2] = LabelVote{q, 2};
    }
    refreshAndCompare();
    registry.merge(p, q);
    refreshAndCompare();
    EXPECT_GT(scan.blocksRead(), 0u);
  }
}

// A write that bypasses the stamping writers is invisible until the block is marked; marked,
// it is read again.
TEST(SurfaceScan, AMarkedBlockIsReadAgain) {
  TsdfMap map(config());
  LabelRegistry registry;
  for (int i = 0; i < kLabels; ++i) registry.create();
  RandomWriter rng(3);
  rng.write(&map, 500, 0, 0, 0, 20);
  SurfaceScan scan;
  scan.refresh(map, registry, 2.0f);
  Block* block = map.blocks().front().get();
  Voxel& v = block->voxels[0];
  v.weight = 1.0f;
  v.sdf_m = 0.0f;
  block->votesToWrite(0)->slots[0] = LabelVote{kLabels, 50};
  scan.refresh(map, registry, 2.0f);
  EXPECT_EQ(scan.blocksRead(), 0u);
  map.markChanged(block);
  scan.refresh(map, registry, 2.0f);
  EXPECT_GT(scan.blocksRead(), 0u);
  expectSame(scan, map, registry);
}

// Writers stamp: a mutable lookup stamps each block it finds with a stamp newer than any
// before; a read-only lookup stamps nothing.
TEST(SurfaceScan, MutableLookupsStampTheBlocksTheyFind) {
  TsdfMap map(config());
  Block* a = map.allocateBlock(BlockIndex(0, 0, 0));
  Block* b = map.allocateBlock(BlockIndex(1, 0, 0));
  EXPECT_EQ(a->changed.load(), 0u);
  {
    VoxelLookup read(map);
    read.findGrid(1, 1, 1);
  }
  EXPECT_EQ(a->changed.load(), 0u);
  MutableVoxelLookup first(map);
  first.findGrid(1, 1, 1);
  const uint64_t stamp = a->changed.load();
  EXPECT_GT(stamp, 0u);
  EXPECT_EQ(b->changed.load(), 0u);
  MutableVoxelLookup second(map);
  second.findGrid(9, 1, 1);
  second.findGrid(2, 1, 1);
  EXPECT_GT(b->changed.load(), stamp);
  EXPECT_EQ(a->changed.load(), b->changed.load());
}

// Another map, even one at the same address, starts the scan afresh.
TEST(SurfaceScan, AnotherMapStartsAfresh) {
  LabelRegistry registry;
  for (int i = 0; i < kLabels; ++i) registry.create();
  SurfaceScan scan;
  auto first = std::make_unique<TsdfMap>(config());
  RandomWriter rng(11);
  rng.write(first.get(), 800, 0, 0, 0, 20);
  scan.refresh(*first, registry, 2.0f);
  const uint64_t first_id = first->id();
  first.reset();
  TsdfMap second(config());
  EXPECT_NE(second.id(), first_id);
  rng.write(&second, 300, 30, 0, 0, 10);
  scan.refresh(second, registry, 2.0f);
  EXPECT_EQ(scan.blocksRead(), second.numBlocks());
  expectSame(scan, second, registry);
  EXPECT_THROW(scan.refresh(second, registry, 0.0f), Error);
}

}  // namespace
}  // namespace panmap
