#include <cmath>

#include <gtest/gtest.h>

#include "panmap/tracking/pose_increment.h"

namespace panmap {
namespace {

TEST(PoseIncrement, ExpAndLogAreInverse) {
  for (const Eigen::Vector3d& theta :
       {Eigen::Vector3d(0.3, -0.2, 0.5), Eigen::Vector3d(1e-9, 0.0, -2e-9),
        Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.0, 3.0, 0.0)}) {
    const Eigen::Matrix3d R = expSo3(theta);
    EXPECT_NEAR((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
    EXPECT_NEAR((logSo3(R) - theta).norm(), 0.0, 1e-12) << theta.transpose();
  }
}

TEST(PoseIncrement, ApplyAndBetweenAreInverse) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = expSo3(Eigen::Vector3d(0.4, 1.1, -0.7));
  T.translation() = Eigen::Vector3d(3.0, -2.0, 1.5);
  Vector6d delta;
  delta << 0.02, -0.01, 0.03, 0.01, -0.02, 0.005;
  const Eigen::Isometry3d moved = applyIncrement(T, delta);
  EXPECT_NEAR((incrementBetween(T, moved) - delta).norm(), 0.0, 1e-12);
  // The rotation is about the camera centre: a pure rotation increment leaves it in place.
  Vector6d turn = Vector6d::Zero();
  turn.tail<3>() = Eigen::Vector3d(0.1, 0.2, 0.3);
  EXPECT_EQ(applyIncrement(T, turn).translation(), T.translation());
}

TEST(PoseIncrement, LeftJacobianMatchesFiniteDifferences) {
  for (const Eigen::Vector3d& theta :
       {Eigen::Vector3d(0.3, -0.2, 0.5), Eigen::Vector3d(2e-5, 1e-5, -3e-5)}) {
    const Eigen::Matrix3d J = leftJacobianSo3(theta);
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-6;
      const Eigen::Vector3d e = Eigen::Vector3d::Unit(k) * h;
      // exp(theta + e) exp(theta)^-1 = exp(J e): its rotation vector over h is J's column.
      const Eigen::Vector3d column = logSo3(expSo3(theta + e) * expSo3(theta).transpose()) / h;
      EXPECT_NEAR((column - J.col(k)).norm(), 0.0, 1e-6) << theta.transpose() << " col " << k;
    }
  }
}

}  // namespace
}  // namespace panmap
