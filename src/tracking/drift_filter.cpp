#include "panmap/tracking/drift_filter.h"

#include <cmath>

#include <Eigen/Cholesky>

#include "panmap/core/error.h"

namespace panmap {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Isometry3d orthonormalised(Eigen::Isometry3d T) {
  T.linear() = Eigen::Quaterniond(T.rotation()).normalized().toRotationMatrix();
  return T;
}

}  // namespace

void DriftFilter::Config::check() const {
  auto positive = [](double x) { return x > 0.0 && std::isfinite(x); };
  auto nonNegative = [](double x) { return x >= 0.0 && std::isfinite(x); };
  if (!nonNegative(drift_per_m)) throw Error("tracking drift_per_m must be >= 0");
  if (!nonNegative(drift_deg_per_m)) throw Error("tracking drift_deg_per_m must be >= 0");
  if (!nonNegative(drift_deg_per_90deg)) throw Error("tracking drift_deg_per_90deg must be >= 0");
  if (!positive(correlation_m)) throw Error("tracking drift_correlation_m must be > 0");
  if (!positive(measurement_sigma_m)) throw Error("tracking measurement_sigma_m must be > 0");
  if (!positive(measurement_sigma_deg)) throw Error("tracking measurement_sigma_deg must be > 0");
}

DriftFilter::DriftFilter(const Config& config) : config_(config) { config_.check(); }

void DriftFilter::restore(const State& state) {
  if (!state.input.matrix().allFinite() || !state.correction.matrix().allFinite() ||
      !state.covariance.allFinite()) {
    throw Error("drift filter state is not finite");
  }
  started_ = state.started;
  input_ = state.input;
  correction_ = state.correction;
  covariance_ = state.covariance;
}

Eigen::Isometry3d DriftFilter::predict(const Eigen::Isometry3d& T_W_C_input) {
  if (!started_) {
    // The map starts in the input's frame: no correction, and no doubt about it.
    started_ = true;
    input_ = T_W_C_input;
    return current();
  }
  const Eigen::Isometry3d motion = input_.inverse() * T_W_C_input;
  const double distance_m = motion.translation().norm();
  const double turn_rad = Eigen::AngleAxisd(motion.rotation()).angle();
  // The same correction seen from the new camera centre: a rotation error now moves the camera
  // by theta x (lever arm), dt' = dt - [dp]x theta.
  const Eigen::Vector3d moved_m =
      (correction_ * T_W_C_input).translation() - current().translation();
  Matrix6d A = Matrix6d::Identity();
  A.topRightCorner<3, 3>() = -skew(moved_m);
  covariance_ = A * covariance_ * A.transpose();
  // Drift since the last input: random walks in translation and rotation.
  const double var_t =
      config_.drift_per_m * config_.drift_per_m * config_.correlation_m * distance_m;
  const double rate_rad = config_.drift_deg_per_m * kDeg;
  const double turn_sigma_rad = config_.drift_deg_per_90deg * kDeg;
  const double var_r = rate_rad * rate_rad * config_.correlation_m * distance_m +
                       turn_sigma_rad * turn_sigma_rad * turn_rad / (M_PI / 2);
  covariance_.diagonal().head<3>().array() += var_t;
  covariance_.diagonal().tail<3>().array() += var_r;
  input_ = T_W_C_input;
  return current();
}

Eigen::Isometry3d DriftFilter::adopt(const Eigen::Isometry3d& T_W_C_refined) {
  if (T_W_C_refined.matrix().allFinite()) {
    correction_ = orthonormalised(T_W_C_refined * input_.inverse());
  }
  return current();
}

Eigen::Isometry3d DriftFilter::update(const Vector6d& delta, const Matrix6d& information) {
  if (!delta.allFinite() || !information.allFinite()) return current();
  // The alignment's covariance plus the floor of what a real-depth alignment is good to.
  Eigen::LDLT<Matrix6d> information_ldlt(information);
  if (information_ldlt.info() != Eigen::Success || !information_ldlt.isPositive()) return current();
  Matrix6d R = information_ldlt.solve(Matrix6d::Identity());
  R = 0.5 * (R + R.transpose());
  const double sigma_r = config_.measurement_sigma_deg * kDeg;
  R.diagonal().head<3>().array() += config_.measurement_sigma_m * config_.measurement_sigma_m;
  R.diagonal().tail<3>().array() += sigma_r * sigma_r;
  const Matrix6d S = covariance_ + R;
  // K = P S^-1 (both symmetric): K^T = S^-1 P.
  const Matrix6d K = S.ldlt().solve(covariance_).transpose();
  const Vector6d step = K * delta;
  if (!step.allFinite()) return current();
  const Eigen::Isometry3d refined = applyIncrement(current(), step);
  correction_ = orthonormalised(refined * input_.inverse());
  // Joseph form: stays symmetric and positive.
  const Matrix6d I_K = Matrix6d::Identity() - K;
  covariance_ = I_K * covariance_ * I_K.transpose() + K * R * K.transpose();
  covariance_ = 0.5 * (covariance_ + covariance_.transpose());
  return current();
}

}  // namespace panmap
