#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "panmap/graph/internal/edge_table.h"

namespace panmap {
namespace {

using Ordered = EdgeTable::OrderedEdges;

// The plain definition, one merge at a time over an ordered map: what the table must equal.
void mergeOneByOne(Ordered* edges, int32_t kept, int32_t gone) {
  std::vector<std::pair<std::pair<int32_t, int32_t>, std::map<int32_t, double>>> moved;
  for (auto e = edges->begin(); e != edges->end();) {
    if (e->first.first == gone || e->first.second == gone) {
      const int32_t other = e->first.first == gone ? e->first.second : e->first.first;
      if (other != kept) moved.emplace_back(std::minmax(kept, other), e->second);
      e = edges->erase(e);
    } else {
      ++e;
    }
  }
  for (const auto& [key, conf] : moved) {
    for (const auto& [cls, c] : conf) (*edges)[key][cls] += c;
  }
}

TEST(EdgeTable, SumsPerClassInClassOrder) {
  EdgeTable t;
  t.add(1, 2, 5, 0.5);
  t.add(1, 2, 5, 0.25);
  t.add(1, 2, 3, 1.0);
  t.add(2, 7, 3, 2.0);
  ASSERT_EQ(t.size(), 2u);
  const EdgeTable::Classes* c = t.find(1, 2);
  ASSERT_NE(c, nullptr);
  ASSERT_EQ(c->size(), 2u);
  EXPECT_EQ((*c)[0], std::make_pair(3, 1.0));
  EXPECT_EQ((*c)[1], std::make_pair(5, 0.75));
  EXPECT_EQ(t.find(1, 7), nullptr);
}

TEST(EdgeTable, MergeMovesEdgesToTheKeptSuperpointAndDropsTheirOwn) {
  EdgeTable t;
  t.add(1, 2, 5, 1.0);
  t.add(2, 3, 5, 2.0);
  t.add(1, 3, 5, 4.0);
  t.add(3, 9, 6, 8.0);
  const std::vector<SuperpointMerge> merges = {{1, 3, 0}};
  t.applyMerges(merges, 0, 1);
  const Ordered expected = {{{1, 2}, {{5, 3.0}}}, {{1, 9}, {{6, 8.0}}}};
  EXPECT_EQ(t.toOrdered(), expected);
}

TEST(EdgeTable, ChainedMergesInOneBatchFollowTheChain) {
  EdgeTable t;
  t.add(3, 4, 1, 1.0);
  t.add(2, 4, 1, 10.0);
  t.add(1, 4, 2, 100.0);
  // 3 -> 2, then 2 -> 1: everything ends on (1, 4).
  const std::vector<SuperpointMerge> merges = {{7, 8, 0}, {2, 3, 0}, {1, 2, 0}};
  t.applyMerges(merges, 1, 3);  // the first merge was applied before
  const Ordered expected = {{{1, 4}, {{1, 11.0}, {2, 100.0}}}};
  EXPECT_EQ(t.toOrdered(), expected);
}

TEST(EdgeTable, RandomMergesGiveTheSameSumsBitForBitAsOneByOne) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> label(1, 40), cls(1, 4), batch(1, 4);
  std::uniform_real_distribution<double> value(0.0, 1.0);
  EdgeTable table;
  Ordered reference;
  std::vector<int32_t> live;
  for (int32_t l = 1; l <= 40; ++l) live.push_back(l);
  std::vector<SuperpointMerge> merges;
  for (int round = 0; round < 60; ++round) {
    for (int k = 0; k < 50; ++k) {
      int32_t a = live[static_cast<size_t>(label(rng)) % live.size()];
      int32_t b = live[static_cast<size_t>(label(rng)) % live.size()];
      if (a == b) continue;
      if (a > b) std::swap(a, b);
      const int32_t c = cls(rng);
      const double v = value(rng);
      table.add(a, b, c, v);
      reference[{a, b}][c] += v;
    }
    // A batch of merges among live super-points, sometimes chained through a kept one.
    const size_t begin = merges.size();
    const int n = batch(rng);
    for (int k = 0; k < n && live.size() > 2; ++k) {
      const size_t i = static_cast<size_t>(label(rng)) % live.size();
      size_t j = static_cast<size_t>(label(rng)) % live.size();
      if (i == j) j = (j + 1) % live.size();
      merges.push_back({live[i], live[j], round});
      mergeOneByOne(&reference, live[i], live[j]);
      live.erase(live.begin() + static_cast<std::ptrdiff_t>(j));
    }
    table.applyMerges(merges, begin, merges.size());
    ASSERT_EQ(table.toOrdered(), reference) << "round " << round;
    if (live.size() <= 2) break;
  }
  EXPECT_GT(merges.size(), 20u);
}

TEST(EdgeTable, KeepIfDropsEdgesWithAnEndLeftOut) {
  EdgeTable t;
  t.add(1, 2, 1, 1.0);
  t.add(2, 3, 1, 1.0);
  t.add(3, 4, 1, 1.0);
  t.keepIf([](int32_t l) { return l != 3; });
  const Ordered expected = {{{1, 2}, {{1, 1.0}}}};
  EXPECT_EQ(t.toOrdered(), expected);
}

TEST(EdgeTable, VisitsInPairOrderAndRoundTripsThroughAnOrderedMap) {
  const Ordered edges = {{{1, 9}, {{2, 0.5}}},
                         {{2, 3}, {{1, 1.5}, {4, 2.5}}},
                         {{2, 10}, {{3, 3.5}}},
                         {{100000, 2000000}, {{40, 4.5}}}};
  EdgeTable t;
  t.add(5, 6, 1, 1.0);  // replaced by assign
  t.assign(edges);
  std::vector<std::pair<int32_t, int32_t>> order;
  t.forEachSorted([&](int32_t a, int32_t b, const EdgeTable::Classes&) {
    order.push_back({a, b});
  });
  const std::vector<std::pair<int32_t, int32_t>> expected_order = {
      {1, 9}, {2, 3}, {2, 10}, {100000, 2000000}};
  EXPECT_EQ(order, expected_order);
  EXPECT_EQ(t.toOrdered(), edges);
}

TEST(EdgeTable, MemoryCountsSlotsAndTheClassesOfPairsWithMoreThanOne) {
  EdgeTable one, two;
  one.add(1, 2, 1, 1.0);
  one.add(3, 4, 1, 1.0);
  two.add(1, 2, 1, 1.0);
  two.add(1, 2, 2, 1.0);
  two.add(3, 4, 1, 1.0);
  const size_t slot = sizeof(std::pair<const uint64_t, EdgeTable::Classes>) + 1;
  EXPECT_GE(one.memoryBytes(), 2 * slot);
  // Same pairs, same table; the second class of (1, 2) moves both to a malloc'd block of two
  // 16-byte entries (32 bytes + 8 of header, rounded to 48).
  EXPECT_EQ(two.memoryBytes() - one.memoryBytes(), 48u);
}

}  // namespace
}  // namespace panmap
