#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "analytic_tsdf.h"
#include "panmap/tracking/sdf_residuals.h"

namespace panmap {
namespace {

// A sphere of radius 1 m mapped at 1 cm, seen from a camera 2.5 m from its centre.
class SphereResiduals : public ::testing::Test {
 protected:
  SphereResiduals() : map_(TsdfMap::Config{0.01f}) {
    test::fillAnalyticTsdf(
        Eigen::AlignedBox3f(Eigen::Vector3f(-1.1f, -1.1f, -1.1f),
                            Eigen::Vector3f(1.1f, 1.1f, 1.1f)),
        0.06f, [](const Eigen::Vector3f& p) { return p.norm() - 1.0f; }, &map_);
    T_W_C_.setIdentity();
    T_W_C_.translation() = Eigen::Vector3d(0.0, 0.0, -2.5);  // optical axis +z toward the centre
  }
  // Points of the sphere's front cap in the camera frame, `offset_m` along the outward normal.
  std::vector<Eigen::Vector3f> capPoints(double offset_m) const {
    std::vector<Eigen::Vector3f> points_C;
    for (int i = -6; i <= 6; ++i) {
      for (int j = -6; j <= 6; ++j) {
        const Eigen::Vector3d n = Eigen::Vector3d(0.1 * i, 0.1 * j, -1.0).normalized();
        points_C.push_back((T_W_C_.inverse() * (n * (1.0 + offset_m))).cast<float>());
      }
    }
    return points_C;
  }
  TsdfMap map_;
  Eigen::Isometry3d T_W_C_;
};

TEST_F(SphereResiduals, ZeroOnTheSurfaceAndTheDistanceOffIt) {
  SdfResidualOptions options;
  options.point_sigma_m = 1.0;   // residuals in metres
  options.robust_scale_m = 1.0;  // and quadratic
  for (double offset : {0.0, 0.02}) {
    SdfResiduals residuals(map_, T_W_C_, capPoints(offset), options);
    std::vector<double> r(residuals.size());
    EXPECT_EQ(residuals.evaluate(Vector6d::Zero(), r.data(), nullptr), residuals.size());
    for (double value : r) EXPECT_NEAR(value, offset, 5e-4);  // trilinear error ~ voxel^2 / R
  }
}

TEST_F(SphereResiduals, DepthNoiseScalesResidualsWithDepthSquared) {
  SdfResidualOptions options;
  options.point_sigma_m = 0.5;
  options.robust_scale_m = 10.0;  // quadratic
  options.depth_noise_at_1m_m = 0.25;
  const std::vector<Eigen::Vector3f> points_C = capPoints(0.02);
  SdfResiduals residuals(map_, T_W_C_, points_C, options);
  std::vector<double> r(residuals.size());
  ASSERT_EQ(residuals.evaluate(Vector6d::Zero(), r.data(), nullptr), residuals.size());
  for (size_t i = 0; i < r.size(); ++i) {
    // sigma(z) = sqrt(0.5^2 + (0.25 z^2)^2): residual = sdf / sigma(z).
    const double z = points_C[i].z();
    const double sigma = std::sqrt(0.25 + std::pow(0.25 * z * z, 2));
    EXPECT_NEAR(r[i], 0.02 / sigma, 5e-4 / sigma) << "z " << z;
  }
}

TEST_F(SphereResiduals, JacobianMatchesFiniteDifferences) {
  for (RobustLoss loss : {RobustLoss::kHuber, RobustLoss::kCauchy}) {
    SdfResidualOptions options;
    options.loss = loss;
    options.robust_scale_m = 0.01;
    options.point_sigma_m = 0.01;
    // Points 2 cm out: beyond the loss scale, so the folded loss is exercised.
    SdfResiduals residuals(map_, T_W_C_, capPoints(0.02), options);
    const int n = residuals.size();
    Vector6d delta;
    delta << 0.003, -0.002, 0.001, 0.002, -0.001, 0.0015;
    std::vector<double> r(n), J(6 * n), r_plus(n), r_minus(n);
    ASSERT_EQ(residuals.evaluate(delta, r.data(), J.data()), n);
    const double h = 1e-4;  // points are floats: smaller steps drown in rounding
    // Relative to the whole Jacobian: the rotation about the optical axis, through the
    // sphere's centre, has (rightly) almost no effect.
    double norm = 0.0;
    for (double value : J) norm += value * value;
    for (int k = 0; k < 6; ++k) {
      Vector6d step = Vector6d::Zero();
      step[k] = h;
      residuals.evaluate(delta + step, r_plus.data(), nullptr);
      residuals.evaluate(delta - step, r_minus.data(), nullptr);
      double error = 0.0;
      for (int i = 0; i < n; ++i) {
        const double numeric = (r_plus[i] - r_minus[i]) / (2 * h);
        error += (numeric - J[6 * i + k]) * (numeric - J[6 * i + k]);
      }
      EXPECT_LT(std::sqrt(error / norm), 1e-3) << "column " << k;
    }
  }
}

TEST_F(SphereResiduals, FoldedLossGivesTheRobustCost) {
  SdfResidualOptions options;
  options.loss = RobustLoss::kCauchy;
  options.robust_scale_m = 0.01;
  options.point_sigma_m = 0.005;
  SdfResiduals residuals(map_, T_W_C_, capPoints(0.03), options);
  std::vector<double> r(residuals.size());
  residuals.evaluate(Vector6d::Zero(), r.data(), nullptr);
  SdfSampler sampler(map_);
  const std::vector<Eigen::Vector3f> points_C = capPoints(0.03);
  for (size_t i = 0; i < points_C.size(); ++i) {
    float sdf = 0.0f;
    ASSERT_TRUE(sampler.sample((T_W_C_ * points_C[i].cast<double>()).cast<float>(), &sdf, nullptr));
    double rho = 0.0, drho = 0.0;
    robustLoss(RobustLoss::kCauchy, 0.01, static_cast<double>(sdf) * sdf, &rho, &drho);
    EXPECT_NEAR(r[i] * r[i], rho / (0.005 * 0.005), 1e-6);
    EXPECT_GT(r[i], 0.0);  // the sign of the distance survives
  }
}

TEST_F(SphereResiduals, PointsOffTheMapAreDroppedAndWeighNothing) {
  std::vector<Eigen::Vector3f> points_C = capPoints(0.0);
  const int on_map = static_cast<int>(points_C.size());
  points_C.push_back(Eigen::Vector3f(0.0f, 0.0f, 1.0f));  // 0.5 m in front: never observed
  points_C.push_back(Eigen::Vector3f(0.0f, 0.0f, 2.0f));  // sphere interior beyond the band
  SdfResiduals residuals(map_, T_W_C_, points_C, SdfResidualOptions{});
  std::vector<double> r(residuals.size()), J(6 * residuals.size());
  EXPECT_EQ(residuals.evaluate(Vector6d::Zero(), r.data(), J.data()), on_map);
  for (int i = on_map; i < residuals.size(); ++i) {
    EXPECT_EQ(r[i], 0.0);
    for (int k = 0; k < 6; ++k) EXPECT_EQ(J[6 * i + k], 0.0);
  }
  EXPECT_EQ(residuals.keepPointsInMap(Vector6d::Zero()), on_map);
  EXPECT_EQ(residuals.size(), on_map);
}

}  // namespace
}  // namespace panmap
