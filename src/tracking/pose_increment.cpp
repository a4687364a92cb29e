#include "panmap/tracking/pose_increment.h"

#include <cmath>

#include "panmap/core/pose.h"

namespace panmap {

Eigen::Matrix3d expSo3(const Eigen::Vector3d& theta_rad) {
  const double angle = theta_rad.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity() + skew(theta_rad);
  return Eigen::AngleAxisd(angle, theta_rad / angle).toRotationMatrix();
}

Eigen::Vector3d logSo3(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d leftJacobianSo3(const Eigen::Vector3d& theta_rad) {
  const double a = theta_rad.norm();
  const Eigen::Matrix3d K = skew(theta_rad);
  // Series below 1e-4 rad: the closed form loses every digit to cancellation there.
  if (a < 1e-4) return Eigen::Matrix3d::Identity() + 0.5 * K + K * K / 6.0;
  const double a2 = a * a;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(a)) / a2 * K +
         (a - std::sin(a)) / (a2 * a) * K * K;
}

Eigen::Isometry3d applyIncrement(const Eigen::Isometry3d& T_W_C, const Vector6d& delta) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = expSo3(delta.tail<3>()) * T_W_C.linear();
  T.translation() = T_W_C.translation() + delta.head<3>();
  return T;
}

Vector6d incrementBetween(const Eigen::Isometry3d& T_W_C_from, const Eigen::Isometry3d& T_W_C_to) {
  Vector6d delta;
  delta.head<3>() = T_W_C_to.translation() - T_W_C_from.translation();
  delta.tail<3>() = logSo3(T_W_C_to.linear() * T_W_C_from.linear().transpose());
  return delta;
}

}  // namespace panmap
