// Applying a SLAM back-end's pose correction to the trajectory the map was built with.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "panmap/loop/pose_correction.h"
#include "test_helpers.h"

namespace panmap {
namespace {

Eigen::Isometry3d pose(double x, double y, double yaw_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0.5);
  return T;
}

// Five frames 100 ms apart along x, each turned a little more.
std::vector<StampedPose> walk() {
  std::vector<StampedPose> trajectory;
  for (int i = 0; i < 5; ++i) {
    StampedPose p;
    p.utime = 1000000 + 100000 * i;
    p.frame_id = i;
    p.T_W_C = pose(0.5 * i, 0.0, 0.1 * i);
    trajectory.push_back(p);
  }
  return trajectory;
}

StampedPose corrected(const StampedPose& old, const Eigen::Isometry3d& D) {
  StampedPose p = old;
  p.T_W_C = D * old.T_W_C;
  return p;
}

void expectPose(const Eigen::Isometry3d& actual, const Eigen::Isometry3d& expected) {
  EXPECT_LT((actual.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-12)
      << "actual\n"
      << actual.matrix() << "\nexpected\n"
      << expected.matrix();
}

TEST(PoseCorrection, OneCorrectedFrameMovesTheWholeTrajectoryRigidly) {
  const std::vector<StampedPose> trajectory = walk();
  const Eigen::Isometry3d D = pose(0.1, -0.2, 0.05);
  PoseCorrection c;
  c.correction_id = 1;
  c.poses = {corrected(trajectory[2], D)};
  const CorrectedTrajectory out = applyCorrection(trajectory, c);
  EXPECT_EQ(out.matched, 1);
  EXPECT_TRUE(out.unknown_utimes.empty());
  ASSERT_EQ(out.poses.size(), trajectory.size());
  for (size_t i = 0; i < trajectory.size(); ++i) {
    expectPose(out.poses[i].T_W_C, D * trajectory[i].T_W_C);
    EXPECT_EQ(out.poses[i].utime, trajectory[i].utime);
    EXPECT_NEAR(out.rotation_rad[i], 0.05, 1e-12);
  }
}

TEST(PoseCorrection, FramesBetweenCorrectedFramesFollowByInterpolation) {
  const std::vector<StampedPose> trajectory = walk();
  // The first frame keeps its pose, the last moves 0.4 m along y and turns 0.2 rad: the loop
  // closure a back-end reports for drift that grew linearly in time.
  Eigen::Isometry3d D4 = Eigen::Isometry3d::Identity();
  D4.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  D4.translation() = Eigen::Vector3d(0.0, 0.4, 0.0);
  PoseCorrection c;
  c.poses = {trajectory[0], corrected(trajectory[4], D4)};
  const CorrectedTrajectory out = applyCorrection(trajectory, c);
  EXPECT_EQ(out.matched, 2);
  for (int i = 0; i < 5; ++i) {
    Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
    D.linear() = Eigen::AngleAxisd(0.05 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    D.translation() = Eigen::Vector3d(0.0, 0.1 * i, 0.0);
    expectPose(out.poses[i].T_W_C, D * trajectory[i].T_W_C);
  }
  EXPECT_NEAR(out.rotation_rad[2], 0.1, 1e-12);
  EXPECT_NEAR(out.max_rotation_rad, 0.2, 1e-12);
  EXPECT_NEAR(out.translation_m[0], 0.0, 1e-12);
}

TEST(PoseCorrection, UnknownUtimesAreNamedAndCountedNotUsed) {
  const std::vector<StampedPose> trajectory = walk();
  const Eigen::Isometry3d D = pose(0.3, 0.0, 0.0);
  PoseCorrection c;
  StampedPose stray = corrected(trajectory[1], pose(5.0, 5.0, 1.0));
  stray.utime = 1150000;  // between frames 1 and 2, 50 ms from both
  c.poses = {stray, corrected(trajectory[3], D)};
  CorrectedTrajectory out = applyCorrection(trajectory, c);
  EXPECT_EQ(out.matched, 1);
  EXPECT_EQ(out.unknown_utimes, std::vector<int64_t>{1150000});
  expectPose(out.poses[0].T_W_C, D * trajectory[0].T_W_C);
  // With a 50 ms tolerance a utime 40 ms after frame 0 matches it.
  c.poses = {corrected(trajectory[0], D)};
  c.poses[0].utime = 1040000;
  EXPECT_EQ(applyCorrection(trajectory, c).matched, 0);
  out = applyCorrection(trajectory, c, 50000);
  EXPECT_EQ(out.matched, 1);
  expectPose(out.poses[4].T_W_C, D * trajectory[4].T_W_C);
  // Nothing matched: the trajectory is unchanged.
  c.poses = {stray};
  out = applyCorrection(trajectory, c);
  EXPECT_EQ(out.matched, 0);
  for (size_t i = 0; i < trajectory.size(); ++i) {
    expectPose(out.poses[i].T_W_C, trajectory[i].T_W_C);
  }
}

TEST(PoseCorrection, BadCorrectionsNameTheirProblem) {
  const std::vector<StampedPose> trajectory = walk();
  PoseCorrection c;
  c.correction_id = 7;
  test::expectError([&] { applyCorrection(trajectory, c); }, {"pose correction 7", "no pose"});
  c.poses = {trajectory[2], trajectory[1]};
  test::expectError([&] { c.check(); }, {"pose correction 7", "increase"});
  c.poses = {trajectory[1]};
  c.poses[0].T_W_C.translation().x() = std::numeric_limits<double>::quiet_NaN();
  test::expectError([&] { c.check(); }, {"pose correction 7", "not rigid"});
  c.poses = {trajectory[1]};
  c.poses[0].T_W_C.linear() *= 1.1;
  test::expectError([&] { c.check(); }, {"1100000", "not rigid"});
  std::vector<StampedPose> unsorted = trajectory;
  std::swap(unsorted[0], unsorted[1]);
  c.poses = {trajectory[1]};
  test::expectError([&] { applyCorrection(unsorted, c); }, {"not sorted"});
}

}  // namespace
}  // namespace panmap

namespace panmap {
namespace {

std::vector<StampedPose> line(int n) {
  std::vector<StampedPose> poses(n);
  for (int i = 0; i < n; ++i) {
    poses[i].utime = 1000 * (i + 1);
    poses[i].T_W_C.translation() = Eigen::Vector3d(0.1 * i, 0.0, 1.0);
  }
  return poses;
}

// Test data of a loop closure: the reference poses of every Nth frame and of the last one,
// exactly, or off by a seeded residual error.
TEST(KeyframeCorrection, EveryNthFrameAndTheLastOneWithTheirReferencePoses) {
  const std::vector<StampedPose> reference = line(7);
  const PoseCorrection c = keyframeCorrection(reference, 4, 9);
  EXPECT_EQ(c.correction_id, 9);
  ASSERT_EQ(c.poses.size(), 3u);  // frames 0, 4 and the last, 6
  EXPECT_EQ(c.poses[0].utime, 1000);
  EXPECT_EQ(c.poses[1].utime, 5000);
  EXPECT_EQ(c.poses[2].utime, 7000);
  EXPECT_EQ(c.poses[1].T_W_C.matrix(), reference[4].T_W_C.matrix());
  EXPECT_EQ(c.utime, 8000 + 1000000 - 1000);  // a second after the last frame
  EXPECT_NO_THROW(c.check());
  EXPECT_EQ(keyframeCorrection(reference, 1).poses.size(), 7u);

  CorrectionResidual residual;
  residual.sigma_m = 0.01;
  residual.sigma_rad = 0.002;
  residual.seed = 5;
  const PoseCorrection noisy = keyframeCorrection(line(301), 1, 1, residual);
  const std::vector<StampedPose> exact = line(301);
  double sum_sq_m = 0.0, sum_sq_rad = 0.0;
  for (size_t i = 0; i < noisy.poses.size(); ++i) {
    const Eigen::Isometry3d E = exact[i].T_W_C.inverse() * noisy.poses[i].T_W_C;
    sum_sq_m += E.translation().squaredNorm();
    sum_sq_rad += std::pow(Eigen::AngleAxisd(E.linear()).angle(), 2);
  }
  // Three axes of sigma each: the RMS offset is sigma * sqrt(3), within sampling error.
  EXPECT_NEAR(std::sqrt(sum_sq_m / 301), 0.01 * std::sqrt(3.0), 0.0015);
  EXPECT_NEAR(std::sqrt(sum_sq_rad / 301), 0.002 * std::sqrt(3.0), 0.0003);
  EXPECT_NO_THROW(noisy.check());
  const PoseCorrection again = keyframeCorrection(line(301), 1, 1, residual);
  EXPECT_EQ(again.poses[17].T_W_C.matrix(), noisy.poses[17].T_W_C.matrix());  // seeded

  EXPECT_THROW(keyframeCorrection({}, 3), Error);
  EXPECT_THROW(keyframeCorrection(reference, 0), Error);
}

TEST(PoseCorrection, AnUnmatchedCorrectionSaysHowFarOffItsUtimesAre) {
  const std::vector<StampedPose> trajectory = walk();
  PoseCorrection c;
  StampedPose a = corrected(trajectory[1], pose(0.1, 0.0, 0.0));
  a.utime = 1150000;  // 50 ms from frames 1 and 2
  StampedPose b = corrected(trajectory[3], pose(0.1, 0.0, 0.0));
  b.utime += 1200;  // 1.2 ms after frame 3: the nearest of the two
  c.poses = {a, b};
  EXPECT_EQ(applyCorrection(trajectory, c, 1000).matched, 0);
  EXPECT_EQ(unmatchedCorrectionReason(trajectory, c, 1000),
            "none of its 2 utimes is a mapped frame (first 1150000, 1200 us from the nearest "
            "mapped frame, tolerance 1000 us)");
  EXPECT_EQ(unmatchedCorrectionReason({}, c, 1000),
            "none of its 2 utimes is a mapped frame (first 1150000, no frame mapped yet)");
}

TEST(PoseCorrection, AWideToleranceGivesNoDroppedFramesPoseToItsNeighbour) {
  // Frames at 1.0, 1.1, 1.3, 1.4 s: the mapper dropped the one at 1.2 s.
  std::vector<StampedPose> trajectory = walk();
  trajectory.erase(trajectory.begin() + 2);
  const Eigen::Isometry3d D = pose(0.3, 0.0, 0.0);
  PoseCorrection c;
  StampedPose dropped = corrected(trajectory[1], pose(5.0, 0.0, 0.0));
  dropped.utime = 1200000;  // 100 ms from both neighbours, within a 150 ms tolerance
  c.poses = {dropped, corrected(trajectory[2], D)};
  CorrectedTrajectory out = applyCorrection(trajectory, c, 150000);
  EXPECT_EQ(out.matched, 1);
  EXPECT_EQ(out.unknown_utimes, std::vector<int64_t>{1200000});
  expectPose(out.poses[1].T_W_C, D * trajectory[1].T_W_C);
  // Two utimes near one frame: the nearer takes it, whichever comes first.
  StampedPose before = corrected(trajectory[1], pose(5.0, 0.0, 0.0));
  before.utime -= 3000;
  StampedPose after = corrected(trajectory[1], D);
  after.utime += 2000;
  c.poses = {before, after};
  out = applyCorrection(trajectory, c, 10000);
  EXPECT_EQ(out.matched, 1);
  EXPECT_EQ(out.unknown_utimes, std::vector<int64_t>{before.utime});
  expectPose(out.poses[1].T_W_C, D * trajectory[1].T_W_C);
  before.utime = trajectory[1].utime - 1000;
  after.utime = trajectory[1].utime + 2000;
  before.T_W_C = D * trajectory[1].T_W_C;
  after.T_W_C = pose(5.0, 0.0, 0.0) * trajectory[1].T_W_C;
  c.poses = {before, after};
  out = applyCorrection(trajectory, c, 10000);
  EXPECT_EQ(out.unknown_utimes, std::vector<int64_t>{after.utime});
  expectPose(out.poses[1].T_W_C, D * trajectory[1].T_W_C);
}

}  // namespace
}  // namespace panmap
