#pragma once

#include <Eigen/Core>

#include "panmap/tracking/pose_increment.h"

namespace panmap {

/// The directions of a pose increment that a normal matrix constrains, after Zhang, Kaess and
/// Singh, "On degeneracy of optimization-based state estimation problems" (ICRA 2016).
///
/// Rotations are measured in metres at the scene's range (angle times length_scale_m) so that
/// translation and rotation eigenvalues compare; the eigenvalues are those of that scaled
/// matrix, ascending. A direction is unconstrained when its eigenvalue is below
/// min_relative_eigenvalue times the largest (a single plane leaves three at zero: the two
/// in-plane translations and the rotation about its normal).
struct DegeneracyAnalysis {
  Vector6d eigenvalues = Vector6d::Zero();   ///< ascending, scaled units
  Matrix6d eigenvectors = Matrix6d::Zero();  ///< columns, scaled coordinates, orthonormal
  int unconstrained = 6;                     ///< directions below the threshold (the first ones)
  double condition_number = 0.0;             ///< largest / smallest eigenvalue (inf if 0)
  double length_scale_m = 1.0;               ///< metres per radian of the scaling

  /// Columns spanning the constrained increments, in increment coordinates (6 x (6 - N)).
  Eigen::Matrix<double, 6, Eigen::Dynamic> constrainedBasis() const;
  /// Maps constrained-subspace coordinates back to an increment: the pseudo-inverse of
  /// constrainedBasis() ((6 - N) x 6).
  Eigen::Matrix<double, Eigen::Dynamic, 6> constrainedCoordinates() const;
  /// Solution remapping: the increment with its unconstrained components removed.
  Vector6d project(const Vector6d& delta) const;
};

/// Eigen-decomposes a normal matrix over increments (pose_increment.h) and classifies its
/// directions.
/// @param normal_matrix J^T W J, increments in (m, rad); any positive overall scale
/// @param length_scale_m metres a radian of rotation counts as (e.g. the RMS point range)
/// @param min_relative_eigenvalue threshold on eigenvalue / largest eigenvalue, in (0, 1)
DegeneracyAnalysis analyseDegeneracy(const Matrix6d& normal_matrix, double length_scale_m,
                                     double min_relative_eigenvalue);

}  // namespace panmap
