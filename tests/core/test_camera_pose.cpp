#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "panmap/core/camera.h"
#include "panmap/core/classes.h"
#include "panmap/core/pose.h"

namespace panmap {
namespace {

TEST(PinholeCamera, ProjectInvertsBackProject) {
  const PinholeCamera cam{585.0, 580.0, 320.0, 240.0, 640, 480};
  const Eigen::Vector3d p = cam.backProject(100.25, 400.5, 2.5);
  Eigen::Vector2d uv;
  ASSERT_TRUE(cam.project(p, &uv));
  EXPECT_NEAR(uv.x(), 100.25, 1e-12);
  EXPECT_NEAR(uv.y(), 400.5, 1e-12);
  EXPECT_DOUBLE_EQ(p.z(), 2.5);
  EXPECT_FALSE(cam.project(Eigen::Vector3d(0, 0, -1), &uv));
}

TEST(PinholeCamera, ResizedKeepsPixelCentres) {
  // ScanNet colour 1296x968 -> 640x480.
  const PinholeCamera cam{1165.723022, 1165.738037, 649.094971, 484.765015, 1296, 968};
  const PinholeCamera small = cam.resized(640, 480);
  const double sx = 640.0 / 1296.0, sy = 480.0 / 968.0;
  EXPECT_DOUBLE_EQ(small.fx, cam.fx * sx);
  EXPECT_DOUBLE_EQ(small.cy, (cam.cy + 0.5) * sy - 0.5);
  // A ray through a pixel centre of the big image hits the matching point of the small one.
  const Eigen::Vector3d p = cam.backProject(1000.0, 100.0, 1.0);
  Eigen::Vector2d uv;
  ASSERT_TRUE(small.project(p, &uv));
  EXPECT_NEAR(uv.x(), (1000.0 + 0.5) * sx - 0.5, 1e-9);
  EXPECT_NEAR(uv.y(), (100.0 + 0.5) * sy - 0.5, 1e-9);
}

TEST(PinholeCamera, ValidityNamesTheProblem) {
  std::string why;
  EXPECT_FALSE((PinholeCamera{0.0, 1.0, 0, 0, 640, 480}.isValid(&why)));
  EXPECT_NE(why.find("focal"), std::string::npos);
  EXPECT_FALSE((PinholeCamera{500, 500, 320, 240, 0, 480}.isValid(&why)));
  EXPECT_NE(why.find("size"), std::string::npos);
  EXPECT_TRUE((PinholeCamera{500, 500, 320, 240, 640, 480}.isValid()));
}

TEST(Pose, RigidTransformCheck) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topRightCorner<3, 1>() << 1, 2, 3;
  EXPECT_TRUE(isRigidTransform(T, 1e-6));
  std::string why;
  Eigen::Matrix4d nan = T;
  nan(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(isRigidTransform(nan, 1e-6, &why));
  EXPECT_NE(why.find("non-finite"), std::string::npos);
  Eigen::Matrix4d inf = T;
  inf.row(0).setConstant(-std::numeric_limits<double>::infinity());
  EXPECT_FALSE(isRigidTransform(inf, 1e-6));
  Eigen::Matrix4d reflection = T;
  reflection(2, 2) = -1.0;
  EXPECT_FALSE(isRigidTransform(reflection, 1e-6, &why));
  EXPECT_NE(why.find("reflection"), std::string::npos);
  Eigen::Matrix4d scaled = T;
  scaled(0, 0) = 1.01;
  EXPECT_FALSE(isRigidTransform(scaled, 1e-3));
  EXPECT_TRUE(isRigidTransform(scaled, 0.05));
}

TEST(Pose, NearestIsometryIsOrthonormalAndClose) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T(0, 1) += 2e-4;  // rounding like a dataset's text file
  const Eigen::Isometry3d iso = nearestIsometry(T);
  EXPECT_NEAR((iso.linear().transpose() * iso.linear() - Eigen::Matrix3d::Identity()).norm(), 0.0,
              1e-12);
  EXPECT_LT((iso.matrix() - T).cwiseAbs().maxCoeff(), 2e-4);
}

TEST(Pose, SkewIsTheCrossProduct) {
  const Eigen::Vector3d v(1.0, -2.0, 3.0), w(0.5, 4.0, -1.5);
  EXPECT_NEAR((skew(v) * w - v.cross(w)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((skew(v) + skew(v).transpose()).norm(), 0.0, 0.0);  // antisymmetric
  EXPECT_DOUBLE_EQ(skew(v)(0, 1), -3.0);
  EXPECT_DOUBLE_EQ(skew(v)(2, 0), 2.0);
}

TEST(Pose, InterpolateMidway) {
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d b = Eigen::Isometry3d::Identity();
  b.translation() << 2.0, 0.0, -4.0;
  b.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Isometry3d mid = interpolatePose(a, b, 0.5);
  EXPECT_TRUE(mid.translation().isApprox(Eigen::Vector3d(1.0, 0.0, -2.0)));
  const Eigen::AngleAxisd aa(mid.linear());
  EXPECT_NEAR(aa.angle(), M_PI / 4, 1e-12);
  EXPECT_NEAR(aa.axis().z(), 1.0, 1e-12);
}

TEST(Classes, Nyu40NamesAndStuff) {
  EXPECT_EQ(nyu40Name(1), "wall");
  EXPECT_EQ(nyu40Name(39), "otherfurniture");
  EXPECT_EQ(nyu40Name(41), "unknown");
  EXPECT_EQ(nyu40IdFromName("Night-Stand"), 32);
  EXPECT_EQ(nyu40IdFromName("refrigerator"), 24);
  EXPECT_EQ(nyu40IdFromName("Shower Curtain"), 28);
  EXPECT_EQ(nyu40IdFromName("spaceship"), 0);
  EXPECT_TRUE(isStuffClass(22));
  EXPECT_FALSE(isStuffClass(5));
  EXPECT_EQ(evaluatedClasses().size(), 18u);
  EXPECT_EQ(evaluatedClasses().front(), 3);
  EXPECT_EQ(evaluatedClasses().back(), 39);
}

}  // namespace
}  // namespace panmap
