// fillMaskEdges: the pixels of a mask that no surface holds take the label of the mask's
// labelled pixels they reach without crossing a depth jump; exact values on tiny images.
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/core/thread_pool.h"
#include "panmap/segmentation/mask_edge_fill.h"

namespace panmap {
namespace {

// A frame of `rows` (one string per image row): a digit is the pixel's super-point label
// (0: none), every pixel has depth 1000 (1 m in mm) unless `depth` says otherwise, and mask
// ids come from `mask_rows` ('.' = no mask, 'a' = mask 1 chair, 'b' = mask 2 table, 'u' =
// mask 3 of an unknown class).
struct Tiny {
  DepthImage depth;
  PanopticFrame masks;
  LabelImage labels;

  Tiny(const std::vector<const char*>& rows, const std::vector<const char*>& mask_rows) {
    const int w = static_cast<int>(std::char_traits<char>::length(rows[0]));
    const int h = static_cast<int>(rows.size());
    depth = DepthImage(w, h, 1000);
    labels = LabelImage(w, h, 0);
    masks.segment_ids = LabelImage(w, h, 0);
    masks.segments = {{1, 5, 5, true, 0.9f}, {2, 7, 7, true, 0.9f}, {3, 0, 99, true, 0.9f}};
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        labels(u, v) = rows[v][u] - '0';
        const char m = mask_rows[v][u];
        masks.segment_ids(u, v) = m == 'a' ? 1 : m == 'b' ? 2 : m == 'u' ? 3 : 0;
      }
    }
  }
  std::vector<int32_t> row(int v) const {
    std::vector<int32_t> out;
    for (int u = 0; u < labels.width(); ++u) out.push_back(labels(u, v));
    return out;
  }
};

TEST(MaskEdgeFill, EdgePixelsOfAMaskTakeItsNearestLabel) {
  // Mask a over everything, labels 7 and 9 with edge pixels (0) between and around them:
  // each takes the label nearest in steps; column 1 is one step from both, and breadth first
  // from the sources in pixel order gives it 7, the first.
  Tiny t({"70900", "00000"}, {"aaaaa", "aaaaa"});
  const int64_t filled = fillMaskEdges(t.depth, t.masks, MaskEdgeFillConfig{}, &t.labels);
  EXPECT_EQ(filled, 8);
  EXPECT_EQ(t.row(0), (std::vector<int32_t>{7, 7, 9, 9, 9}));
  EXPECT_EQ(t.row(1), (std::vector<int32_t>{7, 7, 9, 9, 9}));
}

TEST(MaskEdgeFill, StopsAtOtherMasksUnknownClassesNoMaskAndNoDepth) {
  Tiny t({"5000000", "0000000"}, {"aaab.uu", "aaab.uu"});
  t.depth(2, 1) = 0;  // no depth: never filled, and the fill does not pass through it
  const int64_t filled = fillMaskEdges(t.depth, t.masks, MaskEdgeFillConfig{}, &t.labels);
  EXPECT_EQ(filled, 4);
  EXPECT_EQ(t.row(0), (std::vector<int32_t>{5, 5, 5, 0, 0, 0, 0}));
  EXPECT_EQ(t.row(1), (std::vector<int32_t>{5, 5, 0, 0, 0, 0, 0}));
}

TEST(MaskEdgeFill, StopsAtADepthJumpButFollowsASlope) {
  // 1 m with steps of 9 mm (0.9 %: followed), then a 2 cm jump (2 %: not crossed).
  Tiny t({"30000"}, {"aaaaa"});
  const uint16_t depth_mm[] = {1000, 1009, 1018, 1038, 1047};
  for (int u = 0; u < 5; ++u) t.depth(u, 0) = depth_mm[u];
  const int64_t filled = fillMaskEdges(t.depth, t.masks, MaskEdgeFillConfig{}, &t.labels);
  EXPECT_EQ(filled, 2);
  EXPECT_EQ(t.row(0), (std::vector<int32_t>{3, 3, 3, 0, 0}));
  // A looser step crosses it.
  Tiny loose({"30000"}, {"aaaaa"});
  for (int u = 0; u < 5; ++u) loose.depth(u, 0) = depth_mm[u];
  MaskEdgeFillConfig config;
  config.max_depth_step = 0.025;
  EXPECT_EQ(fillMaskEdges(loose.depth, loose.masks, config, &loose.labels), 4);
}

TEST(MaskEdgeFill, ReachesAtMostMaxDistanceSteps) {
  // A label at each end of a 16-pixel mask: the default (6) leaves the two middle pixels, 7
  // steps from both, unlabelled; no limit fills them from the nearer end (the left one first).
  Tiny t({"5000000000000008"}, {"aaaaaaaaaaaaaaaa"});
  EXPECT_EQ(fillMaskEdges(t.depth, t.masks, MaskEdgeFillConfig{}, &t.labels), 12);
  EXPECT_EQ(t.row(0), (std::vector<int32_t>{5, 5, 5, 5, 5, 5, 5, 0, 0, 8, 8, 8, 8, 8, 8, 8}));
  Tiny unlimited({"5000000000000008"}, {"aaaaaaaaaaaaaaaa"});
  MaskEdgeFillConfig config;
  config.max_distance_px = 0;
  EXPECT_EQ(fillMaskEdges(unlimited.depth, unlimited.masks, config, &unlimited.labels), 14);
  EXPECT_EQ(unlimited.row(0),
            (std::vector<int32_t>{5, 5, 5, 5, 5, 5, 5, 5, 8, 8, 8, 8, 8, 8, 8, 8}));
  config.max_distance_px = -1;
  EXPECT_THROW(config.check(), Error);
}

TEST(MaskEdgeFill, NeverWrapsAroundTheImageEdges) {
  // The last pixel of row 0 and the first of row 1 follow each other in memory but are not
  // neighbours: the label at the end of row 0 must not reach the start of row 1, nor the one
  // at the start of row 1 the end of row 0.
  Tiny end_of_row({"00005", "00000"}, {"bbbba", "a...."});
  EXPECT_EQ(
      fillMaskEdges(end_of_row.depth, end_of_row.masks, MaskEdgeFillConfig{}, &end_of_row.labels),
      0);
  EXPECT_EQ(end_of_row.row(1), (std::vector<int32_t>{0, 0, 0, 0, 0}));
  Tiny start_of_row({"00000", "30000"}, {"bbbba", "a...."});
  EXPECT_EQ(fillMaskEdges(start_of_row.depth, start_of_row.masks, MaskEdgeFillConfig{},
                          &start_of_row.labels),
            0);
  EXPECT_EQ(start_of_row.row(0), (std::vector<int32_t>{0, 0, 0, 0, 0}));
}

TEST(MaskEdgeFill, ReusedScratchGivesWhatAFreshCallGives) {
  // One scratch through a larger frame, then a smaller one: both as without it.
  MaskEdgeFillScratch scratch;
  Tiny big({"7090000", "0000000", "0000008"}, {"aaaaabb", "aaaaabb", "aaaaabb"});
  Tiny big_fresh = big;
  EXPECT_EQ(
      fillMaskEdges(big.depth, big.masks, MaskEdgeFillConfig{}, &big.labels, &scratch),
      fillMaskEdges(big_fresh.depth, big_fresh.masks, MaskEdgeFillConfig{}, &big_fresh.labels));
  EXPECT_EQ(big.labels, big_fresh.labels);
  EXPECT_EQ(big.row(2), (std::vector<int32_t>{7, 7, 9, 9, 9, 8, 8}));
  Tiny small({"000", "040"}, {"aaa", "aaa"});
  EXPECT_EQ(fillMaskEdges(small.depth, small.masks, MaskEdgeFillConfig{}, &small.labels, &scratch),
            5);
  EXPECT_EQ(small.row(0), (std::vector<int32_t>{4, 4, 4}));
  EXPECT_EQ(small.row(1), (std::vector<int32_t>{4, 4, 4}));
}

// A random frame where fills compete: sparse labels, rectangles of three known masks, one of
// an unknown class and none, depth patches that step and holes.
Tiny randomFrame(std::mt19937* rng, int w, int h) {
  std::vector<std::string> rows(static_cast<size_t>(h), std::string(static_cast<size_t>(w), '0'));
  std::vector<std::string> mask_rows(static_cast<size_t>(h),
                                     std::string(static_cast<size_t>(w), 'a'));
  std::uniform_int_distribution<int> u(0, w - 1), v(0, h - 1), digit(1, 9), kind(0, 3);
  std::bernoulli_distribution labelled(0.04);
  for (auto& row : rows) {
    for (char& c : row) c = labelled(*rng) ? static_cast<char>('0' + digit(*rng)) : '0';
  }
  for (int r = 0; r < 12; ++r) {  // mask rectangles
    const int u0 = u(*rng), v0 = v(*rng), u1 = std::min(w, u0 + 1 + u(*rng) / 2),
              v1 = std::min(h, v0 + 1 + v(*rng) / 2);
    const char m = "bu.a"[kind(*rng)];
    for (int y = v0; y < v1; ++y) {
      for (int x = u0; x < u1; ++x) mask_rows[static_cast<size_t>(y)][static_cast<size_t>(x)] = m;
    }
  }
  std::vector<const char*> r, m;
  for (size_t k = 0; k < rows.size(); ++k)
    r.push_back(rows[k].c_str()), m.push_back(mask_rows[k].c_str());
  Tiny t(r, m);
  for (int p = 0; p < 10; ++p) {  // depth patches: 1 % steps and more, and holes
    const int u0 = u(*rng), v0 = v(*rng), u1 = std::min(w, u0 + 1 + u(*rng) / 3),
              v1 = std::min(h, v0 + 1 + v(*rng) / 3);
    const uint16_t value = static_cast<uint16_t>(p % 4 == 0 ? 0 : 1000 + 12 * (p % 3 + 1));
    for (int y = v0; y < v1; ++y) {
      for (int x = u0; x < u1; ++x) t.depth(x, y) = value;
    }
  }
  return t;
}

TEST(MaskEdgeFill, BandsOnSeveralThreadsGiveWhatOneGives) {
  // Each band fills its rows and max_distance_px + 1 rows around them; whatever the number of
  // bands, every label and the count are those of one band over the whole image (ties between
  // sources included: they are settled by the sources' pixel order, which bands keep). Without
  // the margin, 340 of these comparisons fail.
  std::mt19937 rng(7);
  ThreadPool two(2), three(3), five(5);
  int64_t total = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int w = 20 + trial % 17, h = 6 + (trial * 7) % 41;
    const Tiny frame = randomFrame(&rng, w, h);
    MaskEdgeFillConfig config;
    config.max_distance_px = 1 + trial % 7;
    Tiny one = frame;
    const int64_t filled = fillMaskEdges(one.depth, one.masks, config, &one.labels);
    total += filled;
    for (ThreadPool* pool : {&two, &three, &five}) {
      Tiny banded = frame;
      MaskEdgeFillScratch scratch;
      EXPECT_EQ(fillMaskEdges(banded.depth, banded.masks, config, &banded.labels, &scratch, pool),
                filled)
          << "trial " << trial << ", " << pool->size() << " threads";
      EXPECT_EQ(banded.labels, one.labels)
          << "trial " << trial << ", " << pool->size() << " threads";
    }
  }
  EXPECT_GT(total, 1000);  // the frames do fill
}

TEST(MaskEdgeFill, OffOrWithoutMasksChangesNothing) {
  Tiny t({"40000"}, {"aaaaa"});
  MaskEdgeFillConfig off;
  off.enabled = false;
  EXPECT_EQ(fillMaskEdges(t.depth, t.masks, off, &t.labels), 0);
  EXPECT_EQ(t.row(0), (std::vector<int32_t>{4, 0, 0, 0, 0}));
  Tiny bare({"40000"}, {"....."});
  EXPECT_EQ(fillMaskEdges(bare.depth, bare.masks, MaskEdgeFillConfig{}, &bare.labels), 0);
}

TEST(MaskEdgeFill, RefusesBadConfigAndMismatchedSizes) {
  Tiny t({"40000"}, {"aaaaa"});
  MaskEdgeFillConfig bad;
  bad.max_depth_step = -0.1;
  EXPECT_THROW(fillMaskEdges(t.depth, t.masks, bad, &t.labels), Error);
  bad.max_depth_step = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(bad.check(), Error);
  LabelImage small(4, 1, 0);
  EXPECT_THROW(fillMaskEdges(t.depth, t.masks, MaskEdgeFillConfig{}, &small), Error);
  EXPECT_EQ(t.row(0), (std::vector<int32_t>{4, 0, 0, 0, 0}));
}

}  // namespace
}  // namespace panmap
