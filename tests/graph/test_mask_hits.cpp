// The graph update's sort of (mask, voxel) hits against std::sort + std::unique.
#include <algorithm>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/graph/internal/mask_hits.h"

namespace panmap {
namespace {

using internal::MaskHit;
using internal::maskHitVoxelKey;

std::vector<MaskHit> reference(std::vector<MaskHit> hits) {
  std::sort(hits.begin(), hits.end());
  hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
  return hits;
}

void expectSameAsReference(const std::vector<MaskHit>& input) {
  const std::vector<MaskHit> expected = reference(input);
  std::vector<MaskHit> hits = input, scratch;
  internal::sortUniqueHits(&hits, &scratch);
  ASSERT_EQ(hits.size(), expected.size());
  for (size_t i = 0; i < hits.size(); ++i) {
    EXPECT_EQ(hits[i].mask, expected[i].mask) << i;
    EXPECT_EQ(hits[i].voxel, expected[i].voxel) << i;
    EXPECT_EQ(hits[i].label, expected[i].label) << i;
  }
}

// Hits of `masks` masks over a box of voxels [lo, lo + extent)^3, with duplicates; a voxel's
// label is a function of it (one voxel, one super-point), as in the graph update.
std::vector<MaskHit> randomHits(size_t n, int lo, int extent, std::vector<int32_t> masks,
                                uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> coord(lo, lo + extent - 1);
  std::uniform_int_distribution<size_t> pick(0, masks.size() - 1);
  std::vector<MaskHit> hits;
  for (size_t i = 0; i < n; ++i) {
    const int x = coord(rng), y = coord(rng), z = coord(rng);
    hits.push_back({maskHitVoxelKey(x, y, z), masks[pick(rng)], (x * 7 + y * 3 + z) & 0xFF});
    if (i % 5 == 0) hits.push_back(hits.back());  // the same pixel ray twice
  }
  return hits;
}

TEST(MaskHits, SortsAndDedupesLikeStdSort) {
  // A room around the origin: coordinates of both signs, so the wrapped fields span nearly
  // their whole range on x, y and z.
  expectSameAsReference(randomHits(20000, -300, 600, {1, 2, 3, 7, 40}, 1));
  // Positive coordinates only, one mask: few bits per field.
  expectSameAsReference(randomHits(5000, 100, 50, {12}, 2));
  // Mask ids far apart (a large and a negative one) force the 96-bit fallback.
  expectSameAsReference(randomHits(3000, -1000000, 2000000, {-5, 2000000000}, 3));
  // Below the radix threshold.
  expectSameAsReference(randomHits(100, -3, 6, {4, 5}, 4));
}

TEST(MaskHits, EdgeCases) {
  std::vector<MaskHit> empty, scratch;
  internal::sortUniqueHits(&empty, &scratch);
  EXPECT_TRUE(empty.empty());
  // Every hit identical: one digit-free key, one hit left.
  std::vector<MaskHit> same(2000, MaskHit{maskHitVoxelKey(-1, 2, -3), 9, 4});
  internal::sortUniqueHits(&same, &scratch);
  ASSERT_EQ(same.size(), 1u);
  EXPECT_EQ(same[0].voxel, maskHitVoxelKey(-1, 2, -3));
  EXPECT_EQ(same[0].mask, 9);
  EXPECT_EQ(same[0].label, 4);
  // Extreme field values: the wrapped -1 (all ones) and 0 on every axis.
  std::vector<MaskHit> corners;
  for (int i = 0; i < 1024; ++i) {
    corners.push_back({maskHitVoxelKey(i & 1 ? -1 : 0, i & 2 ? -1 : 0, i & 4 ? -1 : 0), i % 3, 1});
  }
  expectSameAsReference(corners);
}

}  // namespace
}  // namespace panmap
