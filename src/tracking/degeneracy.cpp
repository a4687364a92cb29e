#include "panmap/tracking/degeneracy.h"

#include <limits>

#include <Eigen/Eigenvalues>

namespace panmap {
namespace {

// Increment coordinates x from scaled coordinates z: x = S z, rotations divided by the length.
Vector6d scaling(double length_scale_m) {
  Vector6d s;
  s << 1.0, 1.0, 1.0, Eigen::Vector3d::Constant(1.0 / length_scale_m);
  return s;
}

}  // namespace

Eigen::Matrix<double, 6, Eigen::Dynamic> DegeneracyAnalysis::constrainedBasis() const {
  return scaling(length_scale_m).asDiagonal() * eigenvectors.rightCols(6 - unconstrained);
}

Eigen::Matrix<double, Eigen::Dynamic, 6> DegeneracyAnalysis::constrainedCoordinates() const {
  const Vector6d inverse = scaling(length_scale_m).cwiseInverse();
  return eigenvectors.rightCols(6 - unconstrained).transpose() * inverse.asDiagonal();
}

Vector6d DegeneracyAnalysis::project(const Vector6d& delta) const {
  return constrainedBasis() * (constrainedCoordinates() * delta);
}

DegeneracyAnalysis analyseDegeneracy(const Matrix6d& normal_matrix, double length_scale_m,
                                     double min_relative_eigenvalue) {
  DegeneracyAnalysis result;
  result.length_scale_m = length_scale_m;
  const Vector6d s = scaling(length_scale_m);
  const Matrix6d scaled = s.asDiagonal() * normal_matrix * s.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(scaled);
  if (solver.info() != Eigen::Success) return result;  // all six unconstrained
  result.eigenvalues = solver.eigenvalues();
  result.eigenvectors = solver.eigenvectors();
  const double largest = result.eigenvalues[5];
  result.unconstrained = 0;
  if (!(largest > 0.0)) {
    result.unconstrained = 6;
  } else {
    while (result.unconstrained < 6 &&
           result.eigenvalues[result.unconstrained] < min_relative_eigenvalue * largest) {
      ++result.unconstrained;
    }
  }
  result.condition_number = result.eigenvalues[0] > 0.0 ? largest / result.eigenvalues[0]
                                                        : std::numeric_limits<double>::infinity();
  return result;
}

}  // namespace panmap
