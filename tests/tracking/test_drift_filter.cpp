// DriftFilter: covariance growth and lever arm against hand-computed values, the Kalman gain
// on a diagonal case, convergence to a constant drift, and bad measurements ignored.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/tracking/drift_filter.h"

namespace panmap {
namespace {

Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() << x, y, z;
  return T;
}

DriftFilter::Config translationOnly() {
  DriftFilter::Config config;
  config.drift_per_m = 0.02;
  config.drift_deg_per_m = 0.0;
  config.drift_deg_per_90deg = 0.0;
  config.correlation_m = 1.0;
  return config;
}

TEST(DriftFilter, FirstPoseIsTheInputAndCertain) {
  DriftFilter filter(DriftFilter::Config{});
  const Eigen::Isometry3d T = at(1.0, 2.0, 3.0);
  EXPECT_TRUE(filter.predict(T).isApprox(T, 0.0));
  EXPECT_EQ(filter.covariance(), Matrix6d::Zero());
}

TEST(DriftFilter, TranslationVarianceGrowsWithDistance) {
  DriftFilter filter(translationOnly());
  filter.predict(at(0, 0, 0));
  filter.predict(at(0.5, 0, 0));
  filter.predict(at(0.5, 1.5, 0));
  // var = drift^2 * correlation * distance = 0.02^2 * 1 * 2 m.
  const Matrix6d P = filter.covariance();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(P(i, i), 0.0004 * 2.0, 1e-15);
  for (int i = 3; i < 6; ++i) EXPECT_EQ(P(i, i), 0.0);
  EXPECT_NEAR((P.topRightCorner<3, 3>().norm()), 0.0, 1e-15);
}

TEST(DriftFilter, RotationUncertaintyMovesTheCameraThroughTheLeverArm) {
  DriftFilter::Config config;
  config.drift_per_m = 0.0;
  config.drift_deg_per_m = 1.0;
  config.drift_deg_per_90deg = 0.0;
  config.correlation_m = 1.0;
  DriftFilter filter(config);
  filter.predict(at(0, 0, 0));
  filter.predict(at(1, 0, 0));  // rotation variance s^2 = (1 deg)^2 per metre: no lever arm yet
  const double s2 = std::pow(M_PI / 180.0, 2);
  EXPECT_NEAR(filter.covariance()(3, 3), s2, 1e-15);
  EXPECT_EQ(filter.covariance()(1, 1), 0.0);
  filter.predict(at(1, 0, 0) * at(0, 0, 0));  // no motion: nothing changes
  EXPECT_NEAR(filter.covariance()(5, 5), s2, 1e-15);
  filter.predict(at(3, 0, 0));  // 2 m along x: a yaw error now moves the camera along y
  // dt' = dt - [dp]x theta with dp = (2, 0, 0): dt_y = 2 theta_z, dt_z = -2 theta_y, and the
  // rotation variance grew by s^2 * 2 m on the way (after the lever arm is applied).
  const Matrix6d P = filter.covariance();
  EXPECT_NEAR(P(1, 1), 4.0 * s2, 1e-15);
  EXPECT_NEAR(P(2, 2), 4.0 * s2, 1e-15);
  EXPECT_NEAR(P(0, 0), 0.0, 1e-15);
  EXPECT_NEAR(P(1, 5), 2.0 * s2, 1e-15);
  EXPECT_NEAR(P(5, 5), s2 + 2.0 * s2, 1e-15);
}

TEST(DriftFilter, GainOnADiagonalCase) {
  DriftFilter::Config config = translationOnly();
  config.measurement_sigma_m = 0.01;
  DriftFilter filter(config);
  filter.predict(at(0, 0, 0));
  filter.predict(at(0.25, 0, 0));  // P_t = 0.0004 * 0.25 = 1e-4 = R_floor: gain 1/2
  Vector6d delta = Vector6d::Zero();
  delta.head<3>() << 0.02, -0.04, 0.01;
  // An almost exact alignment: its own covariance is negligible next to the floor.
  const Matrix6d information = Matrix6d::Identity() * 1e12;
  const Eigen::Isometry3d refined = filter.update(delta, information);
  const Eigen::Vector3d expected = Eigen::Vector3d(0.25, 0, 0) + 0.5 * delta.head<3>();
  EXPECT_NEAR((refined.translation() - expected).norm(), 0.0, 1e-9);
  EXPECT_NEAR(filter.covariance()(0, 0), 0.5e-4, 1e-12);
  // Rotations had no uncertainty: the measured rotation is ignored.
  delta.tail<3>() << 0.1, 0.0, 0.0;
  const Eigen::Isometry3d again = filter.update(delta, information);
  EXPECT_NEAR(Eigen::AngleAxisd(again.rotation()).angle(), 0.0, 1e-12);
}

TEST(DriftFilter, ConvergesToAConstantOffsetAndKeepsIt) {
  DriftFilter filter(DriftFilter::Config{});
  const Eigen::Vector3d offset(0.03, -0.02, 0.01);
  Eigen::Isometry3d refined;
  for (int k = 0; k < 400; ++k) {
    const Eigen::Isometry3d input = at(0.01 * k, 0.0, 1.0);
    const Eigen::Isometry3d prior = filter.predict(input);
    // The map says the camera is `offset` away from the input: measured from the prior.
    Vector6d delta = Vector6d::Zero();
    delta.head<3>() = input.translation() + offset - prior.translation();
    refined = filter.update(delta, Matrix6d::Identity() * 1e8);
  }
  EXPECT_NEAR((refined.translation() - (at(3.99, 0.0, 1.0).translation() + offset)).norm(), 0.0,
              1e-3);
  EXPECT_NEAR((filter.correction().translation() - offset).norm(), 0.0, 1e-3);
}

TEST(DriftFilter, IgnoresNonFiniteMeasurementsAndRejectsBadConfigs) {
  DriftFilter filter(DriftFilter::Config{});
  filter.predict(at(0, 0, 0));
  const Eigen::Isometry3d prior = filter.predict(at(1, 0, 0));
  Vector6d delta = Vector6d::Zero();
  delta[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(filter.update(delta, Matrix6d::Identity()).isApprox(prior, 0.0));
  EXPECT_TRUE(filter.update(Vector6d::Zero(), -Matrix6d::Identity()).isApprox(prior, 0.0));
  DriftFilter::Config bad;
  bad.measurement_sigma_m = 0.0;
  EXPECT_THROW(DriftFilter{bad}, Error);
  bad = DriftFilter::Config{};
  bad.drift_per_m = -1.0;
  EXPECT_THROW(DriftFilter{bad}, Error);
}

TEST(DriftFilter, AdoptTakesTheRefinedPoseAsItIs) {
  DriftFilter filter(DriftFilter::Config{});
  filter.predict(at(1, 0, 0));
  const Eigen::Isometry3d refined = at(1.02, -0.01, 0.0);
  EXPECT_TRUE(filter.adopt(refined).isApprox(refined, 1e-12));
  // The correction carries over: the next input moved by 1 m lands 1 m from the refined pose.
  EXPECT_TRUE(filter.predict(at(2, 0, 0)).isApprox(at(2.02, -0.01, 0.0), 1e-12));
}

TEST(DriftFilter, StateRoundTrips) {
  DriftFilter a(DriftFilter::Config{});
  a.predict(at(0, 0, 0));
  a.predict(at(0.5, 0.2, 0));
  Vector6d delta;
  delta << 0.01, 0.0, -0.01, 0.002, 0.0, 0.001;
  a.update(delta, Matrix6d::Identity() * 1e6);
  DriftFilter b(DriftFilter::Config{});
  b.restore(a.state());
  EXPECT_TRUE(b.predict(at(0.9, 0.2, 0)).isApprox(a.predict(at(0.9, 0.2, 0)), 0.0));
  EXPECT_EQ(a.covariance(), b.covariance());
}

}  // namespace
}  // namespace panmap
