// OccupancyMap on tiny inputs with exact answers: one ray, OctoMap's arithmetic, segments in
// front of a wall, bad configs and bad frames.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <octomap/octomap_utils.h>

#include "panmap/core/error.h"
#include "panmap/occupancy/occupancy_map.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "test_helpers.h"
#include "test_meshes.h"

namespace panmap {
namespace {

// A one-pixel camera looking along world +x from the centre of cell (0, 0, 0) (centre
// 0.025, 0.025, 0.025 at 5 cm): its single ray runs along the centres of one row of cells.
// fx = 100: a neighbouring row 5 cm off the axis projects at least 5 / z >= 1.4 px away (z <=
// 3.5 m), outside the pixel.
struct SingleRay {
  PinholeCamera camera{100.0, 100.0, 0.0, 0.0, 1, 1};
  Eigen::Isometry3d T_W_C = test::lookAt({0.025, 0.025, 0.025}, {1.025, 0.025, 0.025});
  DepthImage depth{1, 1, 1000};  // 1 m in millimetres: the end point is x = 1.025
  OccupancyMap::Config config() const {
    OccupancyMap::Config c;
    c.pixel_stride = 1;
    return c;
  }
};

Eigen::Vector3d onAxis(double x) { return Eigen::Vector3d(x, 0.025, 0.025); }

TEST(OccupancyMap, SingleRayMarksFreeCellsThenTheEndCell) {
  const SingleRay ray;
  OccupancyMap map(ray.config());
  const OccupancyUpdateStats stats = map.integrate(ray.depth, 0.001, ray.camera, ray.T_W_C);
  // Free: the camera's cell (x = 0.025) and every cell whose far face (centre + 2.5 cm along
  // the ray) lies before the surface at 1.025: centres 0.075 .. 0.975, 19 cells.
  EXPECT_EQ(stats.depth_samples, 1u);
  EXPECT_EQ(stats.occupied_updates, 1u);
  EXPECT_EQ(stats.free_updates, 20u);
  for (int i = 0; i < 20; ++i) {
    EXPECT_EQ(map.occupancyAt(onAxis(0.025 + 0.05 * i)), Occupancy::kFree) << i;
  }
  EXPECT_EQ(map.occupancyAt(onAxis(1.025)), Occupancy::kOccupied);
  EXPECT_EQ(map.occupancyAt(onAxis(1.075)), Occupancy::kUnknown);          // behind the surface
  EXPECT_EQ(map.occupancyAt(onAxis(-0.025)), Occupancy::kUnknown);         // behind the camera
  EXPECT_EQ(map.occupancyAt({0.525, 0.075, 0.025}), Occupancy::kUnknown);  // beside the ray
  EXPECT_EQ(map.occupancyAt({0.525, 0.025, -0.025}), Occupancy::kUnknown);
  // A fresh cell holds exactly one hit or one miss, in OctoMap's float log-odds.
  const OccupancyCell* hit = map.grid().findCell(map.grid().keyOf(onAxis(1.025)));
  const OccupancyCell* miss = map.grid().findCell(map.grid().keyOf(onAxis(0.525)));
  ASSERT_TRUE(hit && miss);
  EXPECT_EQ(hit->log_odds, octomap::logodds(0.7));
  EXPECT_EQ(miss->log_odds, octomap::logodds(0.4));
  // The exported tree says the same everywhere.
  const auto tree = map.toOcTree();
  for (double x = -0.125; x < 1.3; x += 0.05) {
    EXPECT_EQ(occupancyAt(*tree, onAxis(x)), map.occupancyAt(onAxis(x))) << x;
  }
  EXPECT_EQ(tree->getNumLeafNodes(), 21u);  // nothing else was observed (no pruning possible)
}

TEST(OccupancyMap, RepeatedFramesFollowOctomapsClampedArithmetic) {
  const SingleRay ray;
  OccupancyMap map(ray.config());
  octomap::OcTree reference(0.05);  // OctoMap's defaults equal the config's
  const octomap::OcTreeKey hit_key = reference.coordToKey(1.025, 0.025, 0.025);
  const octomap::OcTreeKey miss_key = reference.coordToKey(0.525, 0.025, 0.025);
  for (int frame = 1; frame <= 7; ++frame) {
    map.integrate(ray.depth, 0.001, ray.camera, ray.T_W_C);
    reference.updateNode(hit_key, true);
    reference.updateNode(miss_key, false);
    const OccupancyCell* hit = map.grid().findCell(CellKey(hit_key[0], hit_key[1], hit_key[2]));
    const OccupancyCell* miss = map.grid().findCell(CellKey(miss_key[0], miss_key[1], miss_key[2]));
    ASSERT_TRUE(hit && miss);
    EXPECT_EQ(hit->log_odds, reference.search(hit_key)->getLogOdds()) << frame;
    EXPECT_EQ(miss->log_odds, reference.search(miss_key)->getLogOdds()) << frame;
    EXPECT_EQ(hit->last_frame, static_cast<uint32_t>(frame));
  }
  // Both clamped by now: 7 hits pass 3.48, 7 misses pass -2.
  EXPECT_EQ(map.grid().findCell(CellKey(hit_key[0], hit_key[1], hit_key[2]))->log_odds,
            octomap::logodds(0.971));
  EXPECT_EQ(map.grid().findCell(CellKey(miss_key[0], miss_key[1], miss_key[2]))->log_odds,
            octomap::logodds(0.1192));
  EXPECT_EQ(map.numFrames(), 7u);
}

// A wall at x = 2.01 seen head-on with exact depth from just off the origin.
class WallInFront : public ::testing::Test {
 protected:
  void SetUp() override {
    LabelledMesh mesh;
    test::addQuad(&mesh, {2.01f, -3, -3}, {2.01f, 3, -3}, {2.01f, 3, 3}, {2.01f, -3, 3}, 1, 1, 4);
    const MeshRenderer renderer(mesh);
    DepthNoiseConfig exact;
    exact.enabled = false;
    T_W_C_ = test::lookAt(eye_, eye_ + Eigen::Vector3d::UnitX());
    depth_ = simulateDepth(renderer.render(camera_, T_W_C_), exact, 0);
    map_.integrate(depth_, 0.001, camera_, T_W_C_);
  }
  const Eigen::Vector3d eye_{0.02, 0.01, 0.03};
  const PinholeCamera camera_ = test::kinectCamera();
  Eigen::Isometry3d T_W_C_;
  DepthImage depth_;
  OccupancyMap map_;
};

TEST_F(WallInFront, SegmentsAreFreeBlockedOrUnknown) {
  const auto tree = map_.toOcTree();
  auto expectBoth = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, Occupancy verdict,
                        const Eigen::Vector3d& where) {
    for (const SegmentCheck& check : {map_.checkSegment(a, b), checkSegment(*tree, a, b)}) {
      EXPECT_EQ(check.verdict, verdict) << a.transpose() << " -> " << b.transpose();
      if (verdict != Occupancy::kFree) {
        EXPECT_LT((check.where_W - where).norm(), 1e-6) << check.where_W.transpose();
      }
    }
  };
  // Up to the cell in front of the wall (far face at x = 2.0, before the surface): free.
  expectBoth(eye_, {1.99, 0.01, 0.03}, Occupancy::kFree, Eigen::Vector3d::Zero());
  // Through the wall: blocked in the cell holding x = 2.01.
  expectBoth(eye_, {3.0, 0.01, 0.03}, Occupancy::kOccupied, {2.025, 0.025, 0.025});
  // Back from behind the wall: the first cell is unknown.
  expectBoth({2.6, 0.01, 0.03}, eye_, Occupancy::kUnknown, {2.575, 0.025, 0.025});
  // Straight up from 0.5 m in front of the camera: leaves the field of view (half-angle
  // atan(240 / 525) = 24.6 deg, so z = 0.03 + 0.48 tan = 0.25 at x = 0.5).
  const SegmentCheck up = map_.checkSegment({0.5, 0.01, 0.03}, {0.5, 0.01, 1.0});
  EXPECT_EQ(up.verdict, Occupancy::kUnknown);
  EXPECT_NEAR(up.where_W.z(), 0.275, 0.051);
  EXPECT_EQ(up.cells_checked, static_cast<size_t>(std::lround(up.where_W.z() / 0.05 + 0.5)));
  // A far end beyond the tree's range (+-1638 m at 5 cm): the first non-free cell from A is
  // still the wall, not the far end (which was reported as "unknown at 2000 0 0").
  expectBoth(eye_, {2000.0, 0.01, 0.03}, Occupancy::kOccupied, {2.025, 0.025, 0.025});
  // Leaving the view below, long before the range's edge: where a segment in range says.
  const SegmentCheck below = map_.checkSegment({1.0, 0.01, 0.03}, {1.0, 0.01, -1.0});
  ASSERT_EQ(below.verdict, Occupancy::kUnknown);
  expectBoth({1.0, 0.01, 0.03}, {1.0, 0.01, -5000.0}, Occupancy::kUnknown, below.where_W);
  // A segment inside one cell looks at that cell only.
  EXPECT_EQ(map_.checkSegment({1.0, 0.01, 0.03}, {1.01, 0.02, 0.04}).cells_checked, 1u);
  test::expectError([&] { map_.checkSegment({NAN, 0, 0}, eye_); }, {"finite"});
}

TEST_F(WallInFront, PointsInFrontAreFreeTheWallOccupiedBehindUnknown) {
  EXPECT_EQ(map_.occupancyAt({1.0, 0.4, -0.3}), Occupancy::kFree);
  EXPECT_EQ(map_.occupancyAt({2.01, 0.4, -0.3}), Occupancy::kOccupied);
  EXPECT_EQ(map_.occupancyAt({2.3, 0.4, -0.3}), Occupancy::kUnknown);
  EXPECT_EQ(map_.occupancyAt({1.0, 0.0, 2.0}), Occupancy::kUnknown);  // above the view
  EXPECT_EQ(map_.occupancyAt({1e6, 0.0, 0.0}), Occupancy::kUnknown);  // outside the tree
  test::expectError([&] { map_.occupancyAt({0, 0, INFINITY}); }, {"finite"});
}

TEST(OccupancyMap, ConfigCheckNamesTheBadField) {
  auto expectBad = [](auto edit, const char* field) {
    OccupancyMap::Config c;
    edit(&c);
    test::expectError([&] { c.check(); }, {field});
    test::expectError([&] { OccupancyMap map(c); }, {field});
  };
  expectBad([](OccupancyMap::Config* c) { c->resolution_m = 0.0; }, "resolution_m");
  expectBad([](OccupancyMap::Config* c) { c->resolution_m = NAN; }, "resolution_m");
  expectBad([](OccupancyMap::Config* c) { c->min_depth_m = -1.0; }, "min_depth_m");
  expectBad([](OccupancyMap::Config* c) { c->max_depth_m = 0.05; }, "max_depth_m");
  expectBad([](OccupancyMap::Config* c) { c->pixel_stride = 0; }, "pixel_stride");
  expectBad([](OccupancyMap::Config* c) { c->prob_hit = 0.4; }, "prob_hit");
  expectBad([](OccupancyMap::Config* c) { c->prob_miss = 0.6; }, "prob_miss");
  expectBad([](OccupancyMap::Config* c) { c->clamping_min = 0.5; }, "clamping_min");
  expectBad([](OccupancyMap::Config* c) { c->clamping_max = 1.0; }, "clamping_max");
  expectBad([](OccupancyMap::Config* c) { c->occupancy_threshold = 1.0; }, "occupancy_threshold");
  EXPECT_NO_THROW(OccupancyMap::Config().check());
}

TEST(OccupancyMap, BadFramesThrowAndLeaveTheMapUntouched) {
  const SingleRay ray;
  OccupancyMap map(ray.config());
  map.integrate(ray.depth, 0.001, ray.camera, ray.T_W_C);
  const std::string before = map.toBtBytes();
  const size_t blocks = map.grid().blocks().size();
  auto expectRefused = [&](const DepthImage& depth, double scale, const PinholeCamera& camera,
                           const Eigen::Isometry3d& T_W_C, const std::vector<std::string>& parts) {
    test::expectError([&] { map.integrate(depth, scale, camera, T_W_C); }, parts);
    EXPECT_EQ(map.toBtBytes(), before);
    EXPECT_EQ(map.grid().blocks().size(), blocks);
    EXPECT_EQ(map.numFrames(), 1u);
  };
  Eigen::Isometry3d nan_pose = ray.T_W_C;
  nan_pose.translation().x() = std::numeric_limits<double>::quiet_NaN();
  expectRefused(ray.depth, 0.001, ray.camera, nan_pose, {"pose"});
  Eigen::Isometry3d sheared = ray.T_W_C;
  sheared.linear()(0, 1) += 0.2;
  expectRefused(ray.depth, 0.001, ray.camera, sheared, {"pose"});
  Eigen::Isometry3d far_away = ray.T_W_C;
  far_away.translation().x() = 5000.0;  // the tree spans +-1638 m at 5 cm
  expectRefused(ray.depth, 0.001, ray.camera, far_away, {"pose", "range"});
  far_away.translation().x() = 1e300;
  expectRefused(ray.depth, 0.001, ray.camera, far_away, {"pose", "range"});
  const PinholeCamera kinect = test::kinectCamera();
  expectRefused(DepthImage(320, 240, 1000), 0.001, kinect, ray.T_W_C,
                {"depth is 320x240", "intrinsics say 640x480"});
  expectRefused(DepthImage(), 0.001, kinect, ray.T_W_C, {"empty depth"});
  expectRefused(ray.depth, 0.0, ray.camera, ray.T_W_C, {"depth scale"});
  PinholeCamera bad = ray.camera;
  bad.fx = 0.0;
  expectRefused(ray.depth, 0.001, bad, ray.T_W_C, {"intrinsics", "focal"});
}

}  // namespace
}  // namespace panmap
