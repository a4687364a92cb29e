// FramePrefetcher: frames come back in order, exactly as loaded; a failed load is rethrown for
// its own frame and nothing after it is loaded.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/mapper/frame_prefetcher.h"

namespace panmap {
namespace {

// A 2x1 frame whose depth and label encode its utime.
void fakeFrame(int64_t utime, RgbdFrame* frame, LabelImage* labels) {
  frame->utime = utime;
  frame->depth = DepthImage(2, 1, static_cast<uint16_t>(utime));
  *labels = LabelImage(2, 1, static_cast<int32_t>(utime * 10));
}

TEST(FramePrefetcher, GivesEveryFrameInOrder) {
  std::vector<int64_t> asked;  // the prefetcher's thread only, read after it is joined
  const std::vector<int64_t> utimes = {5, 3, 9, 11, 12};
  std::vector<int64_t> got;
  {
    FramePrefetcher prefetcher(
        [&asked](int64_t utime, RgbdFrame* f, LabelImage* l) {
          asked.push_back(utime);
          fakeFrame(utime, f, l);
        },
        utimes, 2);
    RgbdFrame frame;
    LabelImage labels;
    for (size_t i = 0; i < utimes.size(); ++i) {
      prefetcher.next(&frame, &labels);
      got.push_back(frame.utime);
      EXPECT_EQ(frame.depth(1, 0), static_cast<uint16_t>(utimes[i]));
      EXPECT_EQ(labels(0, 0), static_cast<int32_t>(utimes[i] * 10));
    }
    EXPECT_THROW(prefetcher.next(&frame, &labels), Error);
  }
  EXPECT_EQ(got, utimes);
  EXPECT_EQ(asked, utimes);
}

TEST(FramePrefetcher, AFailedLoadIsRethrownForItsFrameAndLoadingStops) {
  std::vector<int64_t> asked;
  {
    FramePrefetcher prefetcher(
        [&asked](int64_t utime, RgbdFrame* f, LabelImage* l) {
          asked.push_back(utime);
          if (utime == 2) throw Error("frame store: no frame at utime 2");
          fakeFrame(utime, f, l);
        },
        {1, 2, 3, 4}, 3);
    RgbdFrame frame;
    LabelImage labels;
    prefetcher.next(&frame, &labels);
    EXPECT_EQ(frame.utime, 1);
    try {
      prefetcher.next(&frame, &labels);
      FAIL() << "the failed load was not rethrown";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), "frame store: no frame at utime 2");
    }
    EXPECT_THROW(prefetcher.next(&frame, &labels), Error);
  }
  EXPECT_EQ(asked, (std::vector<int64_t>{1, 2}));
}

// Abandoned halfway (a repair superseded): the destructor returns without the rest.
TEST(FramePrefetcher, StopsWhenDestroyedEarly) {
  std::vector<int64_t> utimes;
  for (int64_t k = 0; k < 1000; ++k) utimes.push_back(k);
  size_t asked = 0;
  {
    FramePrefetcher prefetcher(
        [&asked](int64_t utime, RgbdFrame* f, LabelImage* l) {
          ++asked;
          fakeFrame(utime, f, l);
        },
        utimes, 2);
    RgbdFrame frame;
    LabelImage labels;
    prefetcher.next(&frame, &labels);
  }
  EXPECT_LE(asked, 4u);  // the one taken, two ahead, and one under way at most
}

}  // namespace
}  // namespace panmap
