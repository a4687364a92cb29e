// The depth check of auto tracking: exact pattern figures on hand-made cell residuals.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/tracking/depth_pattern_monitor.h"

namespace panmap {
namespace {

using Verdict = DepthPatternMonitor::Verdict;

constexpr int kCells = 16;

DepthPatternMonitor::Config config(int frames) {
  DepthPatternMonitor::Config c;
  c.frames = frames;
  c.max_pattern_m = 0.0012;
  c.min_cell_points = 10;
  c.min_cell_frames = 2;
  c.min_cells = 12;
  return c;
}

// A frame whose cell c has `points` points with mean mean_m(c).
template <typename Mean>
void addFrame(DepthPatternMonitor* monitor, int points, Mean mean_m, Verdict* verdict) {
  std::vector<double> sum(kCells);
  std::vector<int> count(kCells, points);
  for (int c = 0; c < kCells; ++c) sum[c] = mean_m(c) * points;
  *verdict = monitor->add(sum, count);
}

TEST(DepthPatternMonitor, APatternFixedToTheImageIsUncalibratedAfterTheFrames) {
  DepthPatternMonitor monitor(config(4), kCells);
  EXPECT_TRUE(std::isnan(monitor.patternRmsM()));
  // Cells alternate 1 mm short and 3 mm long around a common 1 mm: RMS 2 mm about the mean,
  // the same in every frame.
  auto pattern = [](int c) { return c % 2 == 0 ? 0.001 : -0.003; };
  Verdict v = Verdict::kPending;
  for (int frame = 0; frame < 3; ++frame) {
    addFrame(&monitor, 20, pattern, &v);
    EXPECT_EQ(v, Verdict::kPending) << frame;
    EXPECT_TRUE(std::isnan(monitor.patternRmsM())) << frame;  // the second half has < 2 frames
  }
  addFrame(&monitor, 20, pattern, &v);
  EXPECT_EQ(v, Verdict::kUncalibrated);
  EXPECT_EQ(monitor.frames(), 4);
  EXPECT_NEAR(monitor.patternRmsM(), 0.002, 1e-12);
  // Decided: later frames change nothing.
  addFrame(
      &monitor, 20, [](int) { return 0.0; }, &v);
  EXPECT_EQ(v, Verdict::kUncalibrated);
  EXPECT_EQ(monitor.frames(), 4);
  EXPECT_NEAR(monitor.patternRmsM(), 0.002, 1e-12);
}

TEST(DepthPatternMonitor, WhatTheTwoHalvesDoNotShareIsNoPattern) {
  // Every cell 5 mm long (a rigid shift explains it), plus +-2 mm that flips sign from frame to
  // frame (noise) and +-3 mm whose sign the second half reverses (a view-dependent disagreement).
  DepthPatternMonitor monitor(config(4), kCells);
  Verdict v = Verdict::kPending;
  for (int frame = 0; frame < 4; ++frame) {
    const double noise = frame % 2 == 0 ? 0.002 : -0.002;
    const double view = frame < 2 ? 0.003 : -0.003;
    addFrame(
        &monitor, 15, [&](int c) { return -0.005 + (c % 2 ? 1.0 : -1.0) * (noise + view); }, &v);
  }
  EXPECT_EQ(v, Verdict::kTrusted);
  EXPECT_EQ(monitor.patternRmsM(), 0.0);  // covariance -(3 mm)^2, clamped
}

TEST(DepthPatternMonitor, SparseCellsAreLeftOutAndTooFewKeepItPending) {
  DepthPatternMonitor monitor(config(4), kCells);
  Verdict v = Verdict::kPending;
  // 9 points per cell: below min_cell_points, no cell counts.
  for (int i = 0; i < 4; ++i)
    addFrame(
        &monitor, 9, [](int) { return 0.01; }, &v);
  EXPECT_EQ(v, Verdict::kPending);
  EXPECT_EQ(monitor.frames(), 4);
  // From here on the frames go to the second half: the first half has nothing, so pending.
  for (int i = 0; i < 3; ++i)
    addFrame(
        &monitor, 10, [](int) { return 0.01; }, &v);
  EXPECT_EQ(v, Verdict::kPending);
  EXPECT_TRUE(std::isnan(monitor.patternRmsM()));

  // 11 cells seen in both halves, then a twelfth.
  DepthPatternMonitor other(config(4), kCells);
  auto eleven = [&](int cells) {
    std::vector<double> sum(kCells, 0.0);
    std::vector<int> count(kCells, 0);
    for (int c = 0; c < cells; ++c) count[c] = 10, sum[c] = 10 * (c % 2 ? 0.004 : -0.004);
    return other.add(sum, count);
  };
  for (int i = 0; i < 4; ++i) v = eleven(11);
  EXPECT_EQ(v, Verdict::kPending);
  // 6 cells at -4 mm, 5 at +4 mm: the covariance of two equal halves is their variance.
  EXPECT_NEAR(other.patternRmsM(), std::sqrt(0.004 * 0.004 - std::pow(0.004 / 11, 2)), 1e-12);
  v = eleven(12);                   // the twelfth cell's second-half frames
  EXPECT_EQ(v, Verdict::kPending);  // it has 1 frame in the second half and none in the first
  EXPECT_EQ(other.frames(), 5);
}

TEST(DepthPatternMonitor, NoFramesMeansTrustedAndStateRoundTrips) {
  DepthPatternMonitor off(config(0), kCells);
  EXPECT_EQ(off.verdict(), Verdict::kTrusted);

  auto pattern = [](int c) { return 0.001 * (c % 4); };  // RMS 1.118 mm < 1.2 mm
  DepthPatternMonitor a(config(6), kCells);
  Verdict v = Verdict::kPending;
  for (int i = 0; i < 4; ++i) addFrame(&a, 12, pattern, &v);
  DepthPatternMonitor b(config(6), kCells);
  b.restore(a.state());
  EXPECT_EQ(b.verdict(), Verdict::kPending);
  EXPECT_EQ(b.frames(), 4);
  for (int i = 0; i < 2; ++i) {
    addFrame(&a, 12, pattern, &v);
    addFrame(&b, 12, pattern, &v);
  }
  EXPECT_EQ(a.verdict(), Verdict::kTrusted);
  EXPECT_EQ(b.verdict(), Verdict::kTrusted);
  EXPECT_EQ(a.patternRmsM(), b.patternRmsM());
  EXPECT_NEAR(a.patternRmsM(), std::sqrt(1.25) * 0.001, 1e-12);
  EXPECT_STREQ(DepthPatternMonitor::name(Verdict::kUncalibrated), "uncalibrated");
}

TEST(DepthPatternMonitor, BadInputIsRefusedByName) {
  DepthPatternMonitor::Config bad = config(3);
  bad.frames = -1;
  EXPECT_THROW(DepthPatternMonitor(bad, kCells), Error);
  bad = config(3);
  bad.max_pattern_m = std::nan("");
  EXPECT_THROW(DepthPatternMonitor(bad, kCells), Error);
  EXPECT_THROW(DepthPatternMonitor(config(3), 4), Error);  // fewer cells than min_cells
  DepthPatternMonitor monitor(config(3), kCells);
  try {
    monitor.add(std::vector<double>(3), std::vector<int>(3));
    FAIL() << "mismatched sizes accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("3 cell sums"), std::string::npos) << e.what();
  }
  DepthPatternMonitor::State state = monitor.state();
  state.cell_frames[1].pop_back();
  EXPECT_THROW(monitor.restore(state), Error);
}

}  // namespace
}  // namespace panmap
