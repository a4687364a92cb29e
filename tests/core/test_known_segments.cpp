#include <gtest/gtest.h>

#include "panmap/core/known_segments.h"

namespace panmap {
namespace {

TEST(KnownSegments, HoldsTheSegmentsOfAKnownClassWhateverTheirId) {
  PanopticFrame frame;
  frame.segments = {
      PanopticSegment{3, 5, 5, true, 0.9f},                           // known
      PanopticSegment{4, 0, 0, false, 1.0f},                          // class 0
      PanopticSegment{KnownSegments::kDense + 7, 1, 1, false, 1.0f},  // beyond the flags
      PanopticSegment{kMaxPanopticSegmentId, 2, 2, false, 1.0f}};
  const KnownSegments known(frame);
  EXPECT_FALSE(known.empty());
  EXPECT_TRUE(known.contains(3));
  EXPECT_FALSE(known.contains(4));
  EXPECT_TRUE(known.contains(KnownSegments::kDense + 7));
  EXPECT_TRUE(known.contains(kMaxPanopticSegmentId));
  for (const int32_t other :
       {0, -3, 1, 2, KnownSegments::kDense - 1, KnownSegments::kDense, KnownSegments::kDense + 6}) {
    EXPECT_FALSE(known.contains(other)) << other;
  }
  PanopticFrame unknown;
  unknown.segments = {PanopticSegment{4, 0, 0, false, 1.0f}};
  EXPECT_TRUE(KnownSegments(unknown).empty());
  EXPECT_FALSE(KnownSegments(unknown).contains(4));
}

}  // namespace
}  // namespace panmap
