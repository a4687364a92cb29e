#include <vector>

#include <gtest/gtest.h>

#include "analytic_tsdf.h"
#include "panmap/tracking/degeneracy.h"
#include "panmap/tracking/sdf_residuals.h"

namespace panmap {
namespace {

// Normal matrix of points a_W (about the camera centre) on planes with unit normals n: rows
// [n, a x n] as SdfResiduals forms them.
Matrix6d planeNormalMatrix(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& pn) {
  Matrix6d H = Matrix6d::Zero();
  for (const auto& [a, n] : pn) {
    Vector6d J;
    J << n, a.cross(n);
    H += J * J.transpose();
  }
  return H / static_cast<double>(pn.size());
}

Vector6d translation(const Eigen::Vector3d& t) {
  Vector6d d = Vector6d::Zero();
  d.head<3>() = t;
  return d;
}

Vector6d rotation(const Eigen::Vector3d& theta) {
  Vector6d d = Vector6d::Zero();
  d.tail<3>() = theta;
  return d;
}

TEST(Degeneracy, SinglePlaneLeavesThreeDirections) {
  // Wall x = 2 seen from the origin.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> pn;
  for (int i = -10; i <= 10; ++i) {
    for (int j = -10; j <= 10; ++j) pn.push_back({{2.0, 0.1 * i, 0.08 * j}, {-1.0, 0.0, 0.0}});
  }
  const DegeneracyAnalysis a = analyseDegeneracy(planeNormalMatrix(pn), 2.0, 0.01);
  EXPECT_EQ(a.unconstrained, 3);
  EXPECT_EQ(a.constrainedBasis().cols(), 3);
  // In-plane translations and the rotation about the normal vanish under remapping ...
  for (const Vector6d& u :
       {translation(Eigen::Vector3d::UnitY()), translation(Eigen::Vector3d::UnitZ()),
        rotation(Eigen::Vector3d::UnitX())}) {
    EXPECT_LT(a.project(u).norm(), 1e-12) << u.transpose();
  }
  // ... the normal translation and the two tilts pass unchanged.
  for (const Vector6d& u :
       {translation(Eigen::Vector3d::UnitX()), rotation(Eigen::Vector3d::UnitY()),
        rotation(Eigen::Vector3d::UnitZ())}) {
    EXPECT_LT((a.project(u) - u).norm(), 1e-12) << u.transpose();
  }
}

TEST(Degeneracy, ThreeWallsConstrainEverything) {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> pn;
  for (int i = -5; i <= 5; ++i) {
    for (int j = -5; j <= 5; ++j) {
      pn.push_back({{2.0, 0.1 * i, 0.1 * j}, {-1.0, 0.0, 0.0}});
      pn.push_back({{0.1 * i + 1.5, 1.0, 0.1 * j}, {0.0, -1.0, 0.0}});
      pn.push_back({{0.1 * i + 1.5, 0.1 * j, -1.2}, {0.0, 0.0, 1.0}});
    }
  }
  const DegeneracyAnalysis a = analyseDegeneracy(planeNormalMatrix(pn), 2.0, 0.01);
  EXPECT_EQ(a.unconstrained, 0);
  EXPECT_GT(a.eigenvalues[0], 0.01 * a.eigenvalues[5]);
  EXPECT_LT(a.condition_number, 100.0);
  const Vector6d d = (Vector6d() << 0.01, -0.02, 0.03, 0.001, 0.002, -0.003).finished();
  EXPECT_LT((a.project(d) - d).norm(), 1e-12);
}

TEST(Degeneracy, ZeroMatrixIsUnconstrainedEverywhere) {
  const DegeneracyAnalysis a = analyseDegeneracy(Matrix6d::Zero(), 1.0, 0.01);
  EXPECT_EQ(a.unconstrained, 6);
  EXPECT_EQ(a.project(Vector6d::Ones()), Vector6d::Zero());
}

// From the TSDF: a camera at the centre of a sphere cannot tell its rotations apart.
TEST(Degeneracy, CameraInsideASphereHasFreeRotations) {
  TsdfMap map(TsdfMap::Config{0.02f});
  test::fillAnalyticTsdf(
      Eigen::AlignedBox3f(Eigen::Vector3f::Constant(-1.6f), Eigen::Vector3f::Constant(1.6f)), 0.08f,
      [](const Eigen::Vector3f& p) { return 1.5f - p.norm(); }, &map);
  std::vector<Eigen::Vector3f> points_C;
  for (int i = -8; i <= 8; ++i) {
    for (int j = -6; j <= 6; ++j) {
      points_C.push_back(Eigen::Vector3f(0.1f * i, 0.1f * j, 1.0f).normalized() * 1.5f);
    }
  }
  SdfResiduals residuals(map, Eigen::Isometry3d::Identity(), points_C, SdfResidualOptions{});
  const SdfFitStats stats = residuals.statistics(Vector6d::Zero(), 0.02);
  ASSERT_EQ(stats.points_in_map, static_cast<int>(points_C.size()));
  EXPECT_NEAR(stats.rms_range_m, 1.5, 1e-5);
  const DegeneracyAnalysis a = analyseDegeneracy(stats.normal_matrix, stats.rms_range_m, 0.01);
  EXPECT_EQ(a.unconstrained, 3);
  for (int k = 0; k < 3; ++k) {
    // Remapping removes rotations (up to the trilinear gradient's small deviations from the
    // radial direction) and keeps translations.
    EXPECT_LT(a.project(rotation(Eigen::Vector3d::Unit(k))).norm(), 0.05);
    EXPECT_NEAR(a.project(translation(Eigen::Vector3d::Unit(k))).norm(), 1.0, 0.05);
  }
}

}  // namespace
}  // namespace panmap
