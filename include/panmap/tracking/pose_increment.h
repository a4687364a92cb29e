#pragma once

#include <Eigen/Geometry>

namespace panmap {

/// A 6-DoF pose increment [dt_W (m); dtheta_W (rad)]: a translation and a rotation vector, both
/// along the world axes, the rotation about the camera centre (so a rotation does not move the
/// camera, and metres and radians stay decoupled at any distance from the world origin).
using Vector6d = Eigen::Matrix<double, 6, 1>;
/// A 6x6 matrix over pose increments (normal matrices, information).
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// Rotation matrix of a rotation vector (Rodrigues), radians.
Eigen::Matrix3d expSo3(const Eigen::Vector3d& theta_rad);

/// Rotation vector of a rotation matrix, radians, angle in [0, pi].
Eigen::Vector3d logSo3(const Eigen::Matrix3d& R);

/// Left Jacobian of SO(3): exp(theta + d) = exp(J_l(theta) d) exp(theta) to first order.
Eigen::Matrix3d leftJacobianSo3(const Eigen::Vector3d& theta_rad);

/// The pose T_W_C moved by an increment: R = exp(dtheta_W) R_W_C, t = t_W_C + dt_W.
Eigen::Isometry3d applyIncrement(const Eigen::Isometry3d& T_W_C, const Vector6d& delta);

/// The increment that takes T_W_C_from to T_W_C_to (inverse of applyIncrement).
Vector6d incrementBetween(const Eigen::Isometry3d& T_W_C_from, const Eigen::Isometry3d& T_W_C_to);

}  // namespace panmap
