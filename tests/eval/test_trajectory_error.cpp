// ATE and RPE (TUM benchmark definitions) on trajectories with hand-computed errors.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/eval/trajectory_error.h"
#include "test_helpers.h"

namespace panmap {
namespace {

StampedPose stamped(int64_t utime, const Eigen::Isometry3d& T_W_C) {
  StampedPose p;
  p.utime = utime;
  p.T_W_C = T_W_C;
  return p;
}

Eigen::Isometry3d pose(const Eigen::Vector3d& t, double yaw, double pitch = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  T.translation() = t;
  return T;
}

// The 8 corners of a 2 x 1 x 0.5 m box visited twice, 0.1 s apart, turning as it goes.
std::vector<StampedPose> twoLaps() {
  std::vector<StampedPose> out;
  for (int k = 0; k < 16; ++k) {
    const int c = k % 8;
    const Eigen::Vector3d corner(c & 1 ? 2.0 : 0.0, c & 2 ? 1.0 : 0.0, c & 4 ? 0.5 : 0.0);
    out.push_back(stamped(k * 100000, pose(corner, 0.3 * k, 0.05 * k)));
  }
  return out;
}

TEST(TrajectoryError, RigidlyMovedTrajectoryHasZeroError) {
  const std::vector<StampedPose> gt = twoLaps();
  const Eigen::Isometry3d T = pose(Eigen::Vector3d(5.0, -3.0, 1.5), 2.0, 0.4);
  std::vector<StampedPose> estimate;
  for (const StampedPose& p : gt) estimate.push_back(stamped(p.utime + 7000, T * p.T_W_C));
  TrajectoryErrorConfig config;
  config.rpe_delta_s = 0.3;
  const TrajectoryError e = evaluateTrajectory(estimate, gt, config);
  EXPECT_EQ(e.num_associated, 16u);
  EXPECT_EQ(e.ate_m.count, 16u);
  EXPECT_NEAR(e.ate_m.rmse, 0.0, 1e-9);
  EXPECT_NEAR(e.ate_m.max, 0.0, 1e-9);
  // The alignment found is the inverse of the applied motion.
  EXPECT_NEAR((e.T_gt_est.matrix() - T.inverse().matrix()).norm(), 0.0, 1e-9);
  // Poses 0..12 each have a partner 0.3 s later; relative motion is unchanged by T.
  EXPECT_EQ(e.rpe_m.count, 13u);
  EXPECT_NEAR(e.rpe_m.max, 0.0, 1e-9);
  EXPECT_NEAR(e.rpe_deg.max, 0.0, 1e-7);
}

TEST(TrajectoryError, OffsetSecondLapGivesHalfTheOffset) {
  // The second lap is shifted by d = (0.3, 0.4, 0), |d| = 0.5 m. Both laps have the same
  // centroid, so sum_i s_i (p_i - mean) = 0 for s_i = +-1 per lap: the cross-covariance stays
  // symmetric positive definite, the best rotation is the identity and the best translation
  // d / 2. Every pose is then 0.25 m off: RMSE = mean = median = max = 0.25.
  const std::vector<StampedPose> gt = twoLaps();
  std::vector<StampedPose> estimate = gt;
  for (size_t k = 8; k < 16; ++k) {
    estimate[k].T_W_C.translation() += Eigen::Vector3d(0.3, 0.4, 0.0);
  }
  const TrajectoryError e = evaluateTrajectory(estimate, gt);
  EXPECT_NEAR(e.ate_m.rmse, 0.25, 1e-12);
  EXPECT_NEAR(e.ate_m.mean, 0.25, 1e-12);
  EXPECT_NEAR(e.ate_m.median, 0.25, 1e-12);
  EXPECT_NEAR(e.ate_m.max, 0.25, 1e-12);
  EXPECT_NEAR(e.T_gt_est.translation().norm(), 0.25, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(e.T_gt_est.rotation()).angle(), 0.0, 1e-12);
}

TEST(TrajectoryError, ConstantDriftGivesTheAnalyticRelativeError) {
  // Ground truth drives straight along x at v = 1 m/s; the estimate drives at the same speed
  // along its own x but turns at w = 0.2 rad/s (a circle). Both are constant-velocity motions,
  // so every 1 s relative pose error is the same:
  //   E = (I, (D, 0, 0))^-1 (Rz(wD), (v/w) (sin wD, 1 - cos wD, 0))
  // translation |((v/w) sin wD - vD, (v/w)(1 - cos wD))|, rotation wD.
  const double v = 1.0, w = 0.2, delta = 1.0;
  std::vector<StampedPose> gt, estimate;
  for (int k = 0; k <= 50; ++k) {
    const double t = 0.1 * k;
    gt.push_back(stamped(k * 100000, pose(Eigen::Vector3d(v * t, 0.0, 0.0), 0.0)));
    estimate.push_back(
        stamped(k * 100000,
                pose(Eigen::Vector3d(v / w * std::sin(w * t), v / w * (1.0 - std::cos(w * t)), 0.0),
                     w * t)));
  }
  const TrajectoryError e = evaluateTrajectory(estimate, gt);
  const double expected_m =
      std::hypot(v / w * std::sin(w * delta) - v * delta, v / w * (1.0 - std::cos(w * delta)));
  const double expected_deg = w * delta * 180.0 / M_PI;  // 11.459 degrees
  EXPECT_EQ(e.rpe_m.count, 41u);                         // starts 0.0 .. 4.0 s
  EXPECT_NEAR(e.rpe_m.rmse, expected_m, 1e-12);
  EXPECT_NEAR(e.rpe_m.max, expected_m, 1e-12);
  EXPECT_NEAR(e.rpe_m.mean, expected_m, 1e-12);
  EXPECT_NEAR(e.rpe_deg.rmse, expected_deg, 1e-9);
  EXPECT_NEAR(e.rpe_deg.median, expected_deg, 1e-9);
  EXPECT_NEAR(expected_m, 0.0998889, 1e-7);  // 10 cm per metre driven
}

TEST(TrajectoryError, CameraOffsetFitRemovesALeverArmThatTurnsWithTheRig) {
  // The reference is a second camera on the same rig, 2.5 cm beside the estimate's and 1 cm
  // behind it, in a world moved rigidly: p_gt = T (p_est + R_est d). A rigid fit alone
  // cannot remove d, which turns with each pose; fitted together, both come out exactly.
  const std::vector<StampedPose> estimate = twoLaps();
  const Eigen::Vector3d d(0.025, 0.0, -0.01);
  const Eigen::Isometry3d T = pose(Eigen::Vector3d(1.0, 2.0, -0.5), 0.7, -0.2);
  std::vector<StampedPose> gt;
  for (const StampedPose& p : estimate) {
    Eigen::Isometry3d moved = p.T_W_C;
    moved.translation() += p.T_W_C.linear() * d;
    gt.push_back(stamped(p.utime, T * moved));
  }
  const TrajectoryError rigid = evaluateTrajectory(estimate, gt);
  EXPECT_GT(rigid.ate_m.rmse, 0.005);
  EXPECT_TRUE(rigid.camera_offset_m.isZero());
  TrajectoryErrorConfig config;
  config.fit_camera_offset = true;
  const TrajectoryError fitted = evaluateTrajectory(estimate, gt, config);
  EXPECT_NEAR(fitted.ate_m.max, 0.0, 1e-9);
  EXPECT_NEAR((fitted.camera_offset_m - d).norm(), 0.0, 1e-9);
  EXPECT_NEAR((fitted.T_gt_est.matrix() - T.matrix()).norm(), 0.0, 1e-9);
  EXPECT_NE(formatTrajectoryError(fitted).find("camera offset [m] 0.0250 "), std::string::npos)
      << formatTrajectoryError(fitted);
  EXPECT_NE(formatTrajectoryError(fitted).find(" -0.0100  (|d| 0.0269, fitted)"),
            std::string::npos);
  // Without an offset to find, the fit finds none and the ATE is the rigid one.
  const TrajectoryError none = evaluateTrajectory(estimate, estimate, config);
  EXPECT_NEAR(none.camera_offset_m.norm(), 0.0, 1e-9);
  EXPECT_NEAR(none.ate_m.max, 0.0, 1e-9);
}

TEST(TrajectoryError, ScaleFitRecoversASimilarityWithAndWithoutAnOffset) {
  // The reference is the estimate scaled by 1.07 (a depth scale error, or a monocular
  // trajectory) and moved: p_gt = T (s (p_est + R_est d)). With d = 0 Umeyama's similarity
  // finds s exactly; with d both come out of the joint fit.
  const std::vector<StampedPose> estimate = twoLaps();
  const Eigen::Isometry3d T = pose(Eigen::Vector3d(-1.0, 0.5, 2.0), -1.1, 0.3);
  const double s = 1.07;
  for (const Eigen::Vector3d& d :
       {Eigen::Vector3d::Zero().eval(), Eigen::Vector3d(0.0, -0.03, 0.02)}) {
    std::vector<StampedPose> gt;
    for (const StampedPose& p : estimate) {
      Eigen::Isometry3d moved = p.T_W_C;
      moved.translation() = T * (s * (p.T_W_C.translation() + p.T_W_C.linear() * d));
      moved.linear() = T.linear() * p.T_W_C.linear();
      gt.push_back(stamped(p.utime, moved));
    }
    TrajectoryErrorConfig config;
    config.fit_scale = true;
    config.fit_camera_offset = !d.isZero();
    const TrajectoryError e = evaluateTrajectory(estimate, gt, config);
    EXPECT_NEAR(e.scale, s, 1e-9);
    EXPECT_NEAR(e.ate_m.max, 0.0, 1e-9);
    EXPECT_NEAR((e.camera_offset_m - d).norm(), 0.0, 1e-9);
    EXPECT_NEAR((e.T_gt_est.matrix() - T.matrix()).norm(), 0.0, 1e-9);
    EXPECT_NE(formatTrajectoryError(e).find("scale             1.07000  (fitted)"),
              std::string::npos);
    // A rigid fit leaves the 7 % scale as error.
    EXPECT_GT(evaluateTrajectory(estimate, gt).ate_m.rmse, 0.02);
  }
}

TEST(TrajectoryError, CameraOffsetFitTakesTheLeastNormOffsetWhenTheRigNeverTurns) {
  // Every pose has the same rotation: R_est d is one constant vector, indistinguishable from
  // the alignment's translation. The fit must not invent an offset.
  std::vector<StampedPose> estimate, gt;
  for (int k = 0; k < 10; ++k) {
    const Eigen::Vector3d p(0.1 * k, 0.05 * k * k, 0.0);
    estimate.push_back(stamped(k * 100000, pose(p, 0.3)));
    gt.push_back(stamped(k * 100000, pose(p + Eigen::Vector3d(0.02, 0.0, 0.0), 0.3)));
  }
  TrajectoryErrorConfig config;
  config.fit_camera_offset = true;
  const TrajectoryError e = evaluateTrajectory(estimate, gt, config);
  EXPECT_NEAR(e.ate_m.max, 0.0, 1e-9);
  EXPECT_TRUE(e.camera_offset_m.allFinite());
  EXPECT_LT(e.camera_offset_m.norm(), 0.02 + 1e-9);
  // The rigid fit is already exact: the least-norm step adds no offset at all.
  EXPECT_NEAR(e.camera_offset_m.norm(), 0.0, 1e-9);
}

TEST(TrajectoryError, AssociationIsGreedyByTimeDifference) {
  std::vector<StampedPose> estimate, gt;
  for (int64_t t : {0, 100000, 110000, 500000}) estimate.push_back(stamped(t, pose({0, 0, 0}, 0)));
  // 105000 is 5 ms from both 100000 and 110000: the earlier stamp wins the tie; 119000 then
  // pairs with 110000 (9 ms). 530000 is 30 ms from 500000: too far.
  for (int64_t t : {15000, 105000, 119000, 530000}) gt.push_back(stamped(t, pose({0, 0, 0}, 0)));
  const auto pairs = associateByTime(estimate, gt, 20000);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0], (std::pair<size_t, size_t>{0, 0}));
  EXPECT_EQ(pairs[1], (std::pair<size_t, size_t>{1, 1}));
  EXPECT_EQ(pairs[2], (std::pair<size_t, size_t>{2, 2}));
  // Unsorted input gives the same pairs, in estimate time order.
  std::vector<StampedPose> reversed(estimate.rbegin(), estimate.rend());
  const auto r = associateByTime(reversed, gt, 20000);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0], (std::pair<size_t, size_t>{3, 0}));
  EXPECT_EQ(r[1], (std::pair<size_t, size_t>{2, 1}));
  EXPECT_EQ(r[2], (std::pair<size_t, size_t>{1, 2}));
}

TEST(TrajectoryError, StatsAndBadInput) {
  const ErrorStats s = errorStats({3.0, 1.0, 4.0, 2.0});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4.0));
  EXPECT_EQ(errorStats({}).count, 0u);
  EXPECT_DOUBLE_EQ(errorStats({1.0, 5.0, 2.0}).median, 2.0);

  std::vector<StampedPose> gt = twoLaps(), late = gt;
  for (StampedPose& p : late) p.utime += 50000;  // 50 ms: nothing associates
  test::expectError([&] { evaluateTrajectory(late, gt); }, {"only 0", "0.02"});
  TrajectoryErrorConfig bad;
  bad.rpe_delta_s = 0.0;
  test::expectError([&] { evaluateTrajectory(gt, gt, bad); }, {"rpe_delta_s"});
}

}  // namespace
}  // namespace panmap
