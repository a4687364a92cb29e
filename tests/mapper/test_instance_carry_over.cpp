#include <map>

#include <gtest/gtest.h>

#include "box_scene.h"

#include "panmap/core/error.h"
#include "panmap/core/thread_pool.h"
#include "panmap/mapper/instance_carry_over.h"
#include "panmap/mapper/mapper.h"

namespace panmap {
namespace {

TEST(CarriedInstanceIds, EachNewInstanceTakesTheOldIdItSharesMostSurfaceWith) {
  // New 1 lies mostly on old 4 (and a little on old 2); new 2 on old 2; new 3 shares too few
  // samples with old 1; new 4 has none. Old ids ran up to 5.
  const InstanceOverlap overlap = {{{1, 4}, 40}, {{1, 2}, 6}, {{2, 2}, 30}, {{3, 1}, 2}};
  int32_t next = 0;
  const std::map<int32_t, int32_t> ids = carriedInstanceIds(overlap, 5, 6, &next);
  EXPECT_EQ(ids, (std::map<int32_t, int32_t>{{1, 4}, {2, 2}, {3, 6}, {4, 7}}));
  EXPECT_EQ(next, 8);
}

TEST(CarriedInstanceIds, AnOldIdGoesToOneNewInstanceOnlyAndOnlyForAFairShare) {
  // Old 3 split in two (new 1 and 2): the larger piece keeps 3, the other gets a new id. New 3
  // lies on old 2 (50 of its 60 samples) and a little on old 1. New 4 and 5 tie on old 5: the
  // smaller new id takes it.
  const InstanceOverlap overlap = {{{1, 3}, 20}, {{2, 3}, 25}, {{3, 1}, 10},
                                   {{3, 2}, 50}, {{4, 5}, 8},  {{5, 5}, 8}};
  int32_t next = 0;
  const std::map<int32_t, int32_t> ids = carriedInstanceIds(overlap, 6, 6, &next);
  EXPECT_EQ(ids, (std::map<int32_t, int32_t>{{1, 6}, {2, 3}, {3, 2}, {4, 5}, {5, 7}}));
  EXPECT_EQ(next, 8);
}

TEST(CarriedInstanceIds, WithoutAnOldMapTheIdsStay) {
  int32_t next = 0;
  EXPECT_EQ(carriedInstanceIds({}, 3, 1, &next), (std::map<int32_t, int32_t>{{1, 1}, {2, 2}}));
  EXPECT_EQ(next, 3);
  // Pairs naming instances neither map has are ignored.
  EXPECT_EQ(carriedInstanceIds({{{9, 1}, 50}, {{1, 9}, 50}}, 2, 2, &next),
            (std::map<int32_t, int32_t>{{1, 2}}));
  EXPECT_EQ(next, 3);
}

// An 8x4 frame without depth but at (2, 2), 1.5 m.
RgbdFrame smallFrame() {
  RgbdFrame frame;
  frame.camera.fx = frame.camera.fy = 500.0;
  frame.camera.width = 8;
  frame.camera.height = 4;
  frame.depth = DepthImage(8, 4, uint16_t{0});
  frame.depth(2, 2) = 1500;
  return frame;
}

TEST(SampleFrame, TakesTheMiddleOfEachGridCellWithDepth) {
  RgbdFrame frame = smallFrame();  // (2, 2): a cell middle with depth, as (6, 2) below
  frame.depth(6, 2) = 2000;
  frame.depth(0, 0) = 1000;  // not a cell middle
  const InstanceSampleFrame s = sampleFrame(frame, 7, Eigen::Isometry3d::Identity(), 4);
  EXPECT_EQ(s.index, 7u);
  ASSERT_EQ(s.samples.size(), 2u);
  EXPECT_EQ(s.samples[0].u, 2);
  EXPECT_EQ(s.samples[0].v, 2);
  EXPECT_FLOAT_EQ(s.samples[0].d_m, 1.5f);
  EXPECT_EQ(s.samples[1].u, 6);
  EXPECT_FLOAT_EQ(s.samples[1].d_m, 2.0f);
  EXPECT_THROW(sampleFrame(frame, 0, Eigen::Isometry3d::Identity(), 0), Error);
}

TEST(SampleFrame, CorrectsTheDepthAsTheMapperDoes) {
  const RgbdFrame frame = smallFrame();
  // 1 cm deeper everywhere, at every depth.
  const DepthCalibration calibration(8, 4, 1, 1, 2, 5.0, {0.01f, 0.01f});
  RgbdFrame corrected;
  calibration.apply(frame, &corrected);
  const InstanceSampleFrame s =
      sampleFrame(frame, 0, Eigen::Isometry3d::Identity(), 4, &calibration);
  ASSERT_EQ(s.samples.size(), 1u);
  EXPECT_FLOAT_EQ(s.samples[0].d_m, 1.51f);
  EXPECT_FLOAT_EQ(s.samples[0].d_m,
                  static_cast<float>(corrected.depth(2, 2) * corrected.depth_scale_m));
  const DepthCalibration identity;
  EXPECT_FLOAT_EQ(sampleFrame(frame, 0, Eigen::Isometry3d::Identity(), 4, &identity).samples[0].d_m,
                  1.5f);
}

class InstanceOverlapTest : public BoxScene {};

// Two maps of the same frames at the same poses: every sample sees the same object and the same
// super-point in both, so each instance and each super-point shares its samples with itself
// only; threads change nothing.
TEST_F(InstanceOverlapTest, TheSameFramesAtTheSamePosesPairEachIdWithItself) {
  const auto old_map = run(config(), 4);
  const auto new_map = run(config(), 4);
  std::vector<InstanceSampleFrame> frames;
  for (int k = 0; k < 4; ++k) {
    RgbdFrame frame;
    PanopticFrame panoptic;
    frameAt(k, &frame, &panoptic);
    frames.push_back(sampleFrame(frame, k, pose(k), 16));
  }
  const CarryOverlap serial =
      countCarryOverlap(frames, old_map->trajectory(), old_map->map(), old_map->superpoints(),
                        new_map->map(), new_map->superpoints());
  ThreadPool pool(2);
  const CarryOverlap threaded =
      countCarryOverlap(frames, old_map->trajectory(), old_map->map(), old_map->superpoints(),
                        new_map->map(), new_map->superpoints(), &pool);
  EXPECT_EQ(threaded.instances, serial.instances);
  EXPECT_EQ(threaded.superpoints, serial.superpoints);
  ASSERT_EQ(serial.instances.size(), 2u);  // the cabinet and the fridge
  for (const auto& [ids, samples] : serial.instances) {
    EXPECT_EQ(ids.first, ids.second);
    EXPECT_GT(samples, 20);
  }
  // Walls, floor and the objects' faces: more super-points than objects, each with itself.
  EXPECT_GT(serial.superpoints.size(), 2u);
  for (const auto& [ids, samples] : serial.superpoints) EXPECT_EQ(ids.first, ids.second);
  frames[1].index = 4;  // beyond the trajectory
  EXPECT_THROW(countCarryOverlap(frames, old_map->trajectory(), old_map->map(),
                                 old_map->superpoints(), new_map->map(), new_map->superpoints()),
               Error);
}

// carriedIds() numbers only the ids it is given (a map's live super-points need not be
// consecutive): the others get no entry, and fresh ids follow the old map's.
TEST(CarriedIds, OnlyTheGivenIdsAreNumbered) {
  int32_t next = 0;
  const IdOverlap overlap = {{{4, 7}, 10}, {{9, 2}, 8}, {{6, 3}, 1}};
  EXPECT_EQ(carriedIds(overlap, {4, 6, 11}, 20, &next),
            (std::map<int32_t, int32_t>{{4, 7}, {6, 20}, {11, 21}}));
  EXPECT_EQ(next, 22);
}

}  // namespace
}  // namespace panmap
