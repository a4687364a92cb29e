#include "panmap/mapper/superpoint_rejoin.h"

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/map/tsdf_map.h"
#include "panmap/map/voxel.h"
#include "panmap/superpoint/superpoint_tracker.h"

namespace panmap {
namespace {

// A tracker whose super-points 1..n are roots, each seen in 10 frames as class_of[label].
SuperpointTracker trackerOf(const std::map<int32_t, int32_t>& class_of,
                            const std::map<std::pair<int32_t, int32_t>, int>& apart = {}) {
  SuperpointTracker tracker{SuperpointConfig()};
  SuperpointTracker::Snapshot s;
  const int32_t n = class_of.rbegin()->first;
  for (int32_t label = 0; label <= n; ++label) s.parents.push_back(label);
  for (const auto& [label, cls] : class_of) s.states[label].class_counts[cls] = 10.0;
  s.apart = apart;
  s.frames = 10;
  tracker.restore(s);
  return tracker;
}

// `count` votes for `label` in voxels [first, last) of block (0, 0, 0).
void vote(TsdfMap* map, int32_t label, int first, int last, uint32_t count) {
  Block* block = map->allocateBlock(BlockIndex(0, 0, 0));
  for (int i = first; i < last; ++i) addVotes(block->votesToWrite(i), label, count);
}

TsdfMap::Config mapConfig() {
  TsdfMap::Config c;
  c.voxel_size_m = 0.02f;
  return c;
}

// Super-points 1 and 2 (class 3) come to lie on one surface: they rejoin. 3 and 4 are two
// objects of class 3 side by side, and 5 lies half on each: it joins one of them, never both
// (that would make the two objects one). 6 (class 7) coincides with 4 but is of another class;
// 7 coincided with 1 already before the repair; 8 and 9 coincide but the network showed them
// as two objects in far more frames than they were seen: all three pairs stay apart.
TEST(SuperpointRejoin, JoinsWhatARepairLaysOntoOneSurfaceAndNothingElse) {
  SuperpointTracker tracker = trackerOf(
      {{1, 3}, {2, 3}, {3, 3}, {4, 3}, {5, 3}, {6, 7}, {7, 3}, {8, 3}, {9, 3}}, {{{8, 9}, 30}});
  TsdfMap before(mapConfig()), after(mapConfig());
  for (TsdfMap* map : {&before, &after}) {
    vote(map, 1, 0, 100, 10);
    vote(map, 7, 0, 20, 1);
    vote(map, 3, 200, 300, 10);
    vote(map, 4, 300, 400, 10);
  }
  vote(&before, 2, 100, 200, 10);  // before the repair, 2 lay beside 1
  vote(&after, 2, 0, 100, 5);
  vote(&after, 5, 290, 310, 1);  // half over 3, half over 4
  vote(&after, 6, 300, 400, 5);  // over 4
  vote(&after, 8, 400, 450, 10);
  vote(&after, 9, 400, 450, 10);

  EXPECT_EQ(rejoinCoincidingSuperpoints(after, &before, &tracker), 2u);
  const LabelRegistry& labels = tracker.labels();
  EXPECT_EQ(labels.resolve(2), 1);
  EXPECT_NE(labels.resolve(3), labels.resolve(4));
  EXPECT_TRUE(labels.resolve(5) == 3 || labels.resolve(5) == 4) << labels.resolve(5);
  EXPECT_EQ(labels.resolve(6), 6);
  EXPECT_EQ(labels.resolve(7), 7);
  EXPECT_EQ(labels.resolve(8), 8);
  EXPECT_EQ(labels.resolve(9), 9);
  // The survivor holds the frame counts of both, as a merge in association gives them.
  EXPECT_DOUBLE_EQ(tracker.state(1)->class_counts.at(3), 20.0);
  EXPECT_EQ(tracker.merges().size(), 2u);
}

// The same map before and after (a repair that moved nothing) rejoins nothing.
TEST(SuperpointRejoin, NothingMovedNothingRejoins) {
  SuperpointTracker tracker = trackerOf({{1, 3}, {2, 3}});
  TsdfMap map(mapConfig());
  vote(&map, 1, 0, 100, 10);
  vote(&map, 2, 0, 100, 5);
  EXPECT_EQ(rejoinCoincidingSuperpoints(map, &map, &tracker), 0u);
  EXPECT_EQ(rejoinCoincidingSuperpoints(map, nullptr, &tracker), 1u);
  EXPECT_EQ(tracker.labels().resolve(2), 1);
}

}  // namespace
}  // namespace panmap
