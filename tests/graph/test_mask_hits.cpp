// The graph update's sort of (mask, voxel) hits against std::sort + std::unique.
#include <algorithm>
#include <random>
#include <string>
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

// Rows of a small id image, one character per pixel ('0'-'9' the id), and back.
Image<int32_t> ids(const std::vector<std::string>& rows) {
  Image<int32_t> image(static_cast<int>(rows[0].size()), static_cast<int>(rows.size()));
  for (size_t v = 0; v < rows.size(); ++v) {
    for (size_t u = 0; u < rows[v].size(); ++u) {
      image(static_cast<int>(u), static_cast<int>(v)) = rows[v][u] - '0';
    }
  }
  return image;
}

std::vector<std::string> rowsOf(const Image<uint8_t>& image) {
  std::vector<std::string> rows;
  for (int v = 0; v < image.height(); ++v) {
    std::string row;
    for (int u = 0; u < image.width(); ++u) row += static_cast<char>('0' + image(u, v));
    rows.push_back(row);
  }
  return rows;
}

TEST(MaskHits, InteriorLeavesOutTheBandAlongEveryOutline) {
  // Mask 1 left, mask 2 right, no mask (0) in a corner; the image's own border is no outline.
  const Image<int32_t> image = ids({"11111122",  //
                                    "11111122",  //
                                    "11111122",  //
                                    "11111122",  //
                                    "00111122"});
  Image<uint8_t> interior;
  internal::maskInterior(image, 1, &interior);
  // Radius 1: the pixels on either side of an outline (4-neighbours differ) and no-mask pixels.
  EXPECT_EQ(rowsOf(interior), (std::vector<std::string>{"11111001",  //
                                                        "11111001",  //
                                                        "11111001",  //
                                                        "00111001",  //
                                                        "00011001"}));
  internal::maskInterior(image, 2, &interior);
  // Radius 2: also every pixel whose 3 x 3 neighbourhood holds one of those.
  EXPECT_EQ(rowsOf(interior), (std::vector<std::string>{"11110000",  //
                                                        "11110000",  //
                                                        "00010000",  //
                                                        "00000000",  //
                                                        "00000000"}));
  // Along one row: radius r leaves out r pixels on each side of the outline.
  internal::maskInterior(ids({"111111111222"}), 2, &interior);
  EXPECT_EQ(rowsOf(interior), (std::vector<std::string>{"111111100001"}));
  internal::maskInterior(ids({"111111111222"}), 3, &interior);
  EXPECT_EQ(rowsOf(interior), (std::vector<std::string>{"111111000000"}));
}

TEST(MaskHits, KeysKeepTheMaskAndSortItsTwoKindsTogether) {
  for (const int32_t id : {1, 7, internal::kMaxMaskHitId}) {
    for (const bool interior : {false, true}) {
      const int32_t key = internal::maskHitKey(id, interior);
      EXPECT_EQ(internal::maskOfHitKey(key), id);
      EXPECT_EQ(key % 2 == 1, interior);
    }
    EXPECT_EQ(internal::maskHitKey(id, true), internal::maskHitKey(id, false) + 1);
  }
  EXPECT_LT(internal::maskHitKey(7, true), internal::maskHitKey(8, false));
}

}  // namespace
}  // namespace panmap
