// OccupancyLane: frames integrated on the lane's thread give the tree a plain sequence of
// OccupancyMap::integrate calls gives, byte for byte; bad frames are refused at push().
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/occupancy/occupancy_lane.h"
#include "panmap/occupancy/occupancy_map.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "test_helpers.h"
#include "test_meshes.h"

namespace panmap {
namespace {

// A box of four walls and a floor seen from 7 poses turning about the vertical: each frame
// frees and hits cells that earlier frames set, so the order of the updates shows in the tree.
class OccupancyLaneViews : public ::testing::Test {
 protected:
  void SetUp() override {
    LabelledMesh mesh;
    test::addQuad(&mesh, {2, -2, -1}, {2, 2, -1}, {2, 2, 2}, {2, -2, 2}, 1, 1, 4);
    test::addQuad(&mesh, {-2, -2, -1}, {-2, 2, -1}, {-2, 2, 2}, {-2, -2, 2}, 1, 1, 4);
    test::addQuad(&mesh, {-2, 2, -1}, {2, 2, -1}, {2, 2, 2}, {-2, 2, 2}, 1, 1, 4);
    test::addQuad(&mesh, {-2, -2, -1}, {2, -2, -1}, {2, -2, 2}, {-2, -2, 2}, 1, 1, 4);
    test::addQuad(&mesh, {-2, -2, -1}, {2, -2, -1}, {2, 2, -1}, {-2, 2, -1}, 2, 2, 4);
    const MeshRenderer renderer(mesh);
    DepthNoiseConfig noise;  // noisy depth: cells flip between hit and free across frames
    for (int k = 0; k < 7; ++k) {
      const double a = 0.6 * k;
      const Eigen::Vector3d eye(0.3 * std::cos(a), 0.3 * std::sin(a), 0.2);
      const Eigen::Vector3d at = eye + Eigen::Vector3d(std::cos(a + 1.0), std::sin(a + 1.0), -0.3);
      poses_.push_back(test::lookAt(eye, at));
      depths_.push_back(simulateDepth(renderer.render(camera_, poses_.back()), noise, k));
    }
  }
  std::string sequential() const {
    OccupancyMap map(config_);
    for (size_t k = 0; k < poses_.size(); ++k) {
      map.integrate(depths_[k], 0.001, camera_, poses_[k]);
    }
    return map.toBtBytes();
  }
  OccupancyMap::Config config_;
  const PinholeCamera camera_ = test::kinectCamera();
  std::vector<Eigen::Isometry3d> poses_;
  std::vector<DepthImage> depths_;
};

TEST_F(OccupancyLaneViews, TheLaneGivesTheTreeOfIntegratingInOrder) {
  const std::string expected = sequential();
  // Capacity 1 waits on every frame; 2 and 3 wrap their ring of buffers several times.
  for (size_t capacity : {1u, 2u, 3u, 16u}) {
    OccupancyMap map(config_);
    {
      OccupancyLane lane(&map, capacity);
      for (size_t k = 0; k < poses_.size(); ++k) {
        lane.push(depths_[k], 0.001, camera_, poses_[k]);
      }
      lane.finish();
      EXPECT_EQ(map.numFrames(), poses_.size()) << capacity;
      EXPECT_EQ(map.toBtBytes(), expected) << capacity;
    }
    EXPECT_EQ(map.toBtBytes(), expected) << capacity;
  }
}

TEST_F(OccupancyLaneViews, TheLaneCopiesTheDepthItIsGiven) {
  const std::string expected = sequential();
  OccupancyMap map(config_);
  OccupancyLane lane(&map, 4);
  DepthImage scratch;
  for (size_t k = 0; k < poses_.size(); ++k) {
    scratch = depths_[k];
    lane.push(scratch, 0.001, camera_, poses_[k]);
    scratch = DepthImage(camera_.width, camera_.height, 0);  // overwritten at once, as a caller may
  }
  lane.finish();
  EXPECT_EQ(map.toBtBytes(), expected);
}

TEST_F(OccupancyLaneViews, DestroyingTheLaneIntegratesWhatIsQueued) {
  const std::string expected = sequential();
  OccupancyMap map(config_);
  {
    OccupancyLane lane(&map, 8);
    for (size_t k = 0; k < poses_.size(); ++k) {
      lane.push(depths_[k], 0.001, camera_, poses_[k]);
    }
  }
  EXPECT_EQ(map.numFrames(), poses_.size());
  EXPECT_EQ(map.toBtBytes(), expected);
}

TEST_F(OccupancyLaneViews, ABadFrameIsRefusedAtPushAndTheOthersGoOn) {
  const std::string expected = sequential();
  OccupancyMap map(config_);
  OccupancyLane lane(&map, 2);
  Eigen::Isometry3d sheared = poses_[0];
  sheared.linear()(0, 1) += 0.2;
  for (size_t k = 0; k < poses_.size(); ++k) {
    lane.push(depths_[k], 0.001, camera_, poses_[k]);
    if (k == 2) {
      test::expectError([&] { lane.push(depths_[k], 0.001, camera_, sheared); }, {"pose"});
      test::expectError([&] { lane.push(DepthImage(320, 240, 1000), 0.001, camera_, poses_[k]); },
                        {"depth is 320x240", "intrinsics say 640x480"});
      test::expectError([&] { lane.push(depths_[k], 0.0, camera_, poses_[k]); }, {"depth scale"});
    }
  }
  EXPECT_NO_THROW(lane.finish());
  EXPECT_EQ(map.numFrames(), poses_.size());
  EXPECT_EQ(map.toBtBytes(), expected);
}

TEST(OccupancyLane, NeedsAMapAndRoom) {
  OccupancyMap map;
  test::expectError([] { OccupancyLane lane(nullptr); }, {"no occupancy map"});
  test::expectError([&] { OccupancyLane lane(&map, 0); }, {"capacity"});
}

}  // namespace
}  // namespace panmap
