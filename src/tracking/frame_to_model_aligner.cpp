#include "panmap/tracking/frame_to_model_aligner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <ceres/ceres.h>

#include "panmap/core/error.h"
#include "panmap/core/pose.h"
#include "panmap/tracking/degeneracy.h"

namespace panmap {
namespace {

// Every point of a level in one cost function, one residual each, the robust loss folded in
// (SdfResiduals): a residual block per point would cost Ceres more than the TSDF lookups.
class SdfCost : public ceres::CostFunction {
 public:
  explicit SdfCost(SdfResiduals* residuals) : residuals_(residuals) {
    set_num_residuals(residuals->size());
    mutable_parameter_block_sizes()->push_back(6);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals_->evaluate(Eigen::Map<const Vector6d>(parameters[0]), residuals,
                         jacobians ? jacobians[0] : nullptr);
    return true;
  }

 private:
  SdfResiduals* residuals_;  // not owned
};

// Prior on the increment to the SLAM pose:
//   r = W delta,  W = diag(1 / sigma_t (x3), 1 / sigma_theta (x3)),
// a Gaussian centred on the SLAM pose; it also keeps weakly observed directions in place.
class PriorCost : public ceres::SizedCostFunction<6, 6> {
 public:
  PriorCost(double sigma_translation_m, double sigma_rotation_rad) {
    weights_ << Eigen::Vector3d::Constant(1.0 / sigma_translation_m),
        Eigen::Vector3d::Constant(1.0 / sigma_rotation_rad);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    Eigen::Map<Vector6d> r(residuals);
    r = weights_.cwiseProduct(Eigen::Map<const Vector6d>(parameters[0]));
    if (jacobians && jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> J(jacobians[0]);
      J = weights_.asDiagonal();
    }
    return true;
  }

 private:
  Vector6d weights_;  // inverse sigmas
};

// Solution remapping: increments confined to the constrained subspace, delta = delta_0 + B y
// with B the constrained eigen-directions, so the optimiser cannot move along the others.
class SubspaceManifold : public ceres::Manifold {
 public:
  explicit SubspaceManifold(const DegeneracyAnalysis& analysis)
      : basis_(analysis.constrainedBasis()), coordinates_(analysis.constrainedCoordinates()) {}
  int AmbientSize() const override { return 6; }
  int TangentSize() const override { return static_cast<int>(basis_.cols()); }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    Eigen::Map<Vector6d> out(x_plus_delta);
    out = Eigen::Map<const Vector6d>(x) +
          basis_ * Eigen::Map<const Eigen::VectorXd>(delta, basis_.cols());
    return true;
  }
  bool PlusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>> J(jacobian, 6,
                                                                            basis_.cols());
    J = basis_;
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    Eigen::Map<Eigen::VectorXd> out(y_minus_x, basis_.cols());
    out = coordinates_ * (Eigen::Map<const Vector6d>(y) - Eigen::Map<const Vector6d>(x));
    return true;
  }
  bool MinusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>> J(jacobian, basis_.cols(),
                                                                            6);
    J = coordinates_;
    return true;
  }

 private:
  Eigen::Matrix<double, 6, Eigen::Dynamic> basis_;
  Eigen::Matrix<double, Eigen::Dynamic, 6> coordinates_;
};

// Back-projected depth pixels on a grid of `stride` (offset by half a stride so that levels
// sample different pixels), within the depth range.
std::vector<Eigen::Vector3f> selectPoints(const DepthImage& depth, const PinholeCamera& camera,
                                          double depth_scale_m, int stride, double min_depth_m,
                                          double max_depth_m) {
  std::vector<Eigen::Vector3f> points_C;
  points_C.reserve(static_cast<size_t>(depth.width() / stride + 1) * (depth.height() / stride + 1));
  for (int v = stride / 2; v < depth.height(); v += stride) {
    for (int u = stride / 2; u < depth.width(); u += stride) {
      const double z_m = depth(u, v) * depth_scale_m;
      if (z_m <= 0.0 || z_m < min_depth_m || z_m > max_depth_m) continue;
      points_C.push_back(camera.backProject(u, v, z_m).cast<float>());
    }
  }
  return points_C;
}

// AlignmentResult::cell_sum_m and cell_count at `delta`.
void cellResiduals(SdfResiduals* residuals, const Vector6d& delta, const PinholeCamera& camera,
                   double inlier_distance_m, AlignmentResult* result) {
  constexpr int kCells = kResidualCellsX * kResidualCellsY;
  result->cell_sum_m.assign(kCells, 0.0);
  result->cell_count.assign(kCells, 0);
  for (const SdfResiduals::RayDistance& d : residuals->rayDistances(delta)) {
    if (!(std::abs(d.along_ray_m) <= inlier_distance_m) || !(d.p_C.z() > 0.0f)) continue;
    const double u = camera.fx * d.p_C.x() / d.p_C.z() + camera.cx;
    const double v = camera.fy * d.p_C.y() / d.p_C.z() + camera.cy;
    const int cx =
        std::clamp(static_cast<int>(u * kResidualCellsX / camera.width), 0, kResidualCellsX - 1);
    const int cy =
        std::clamp(static_cast<int>(v * kResidualCellsY / camera.height), 0, kResidualCellsY - 1);
    result->cell_sum_m[cy * kResidualCellsX + cx] += d.along_ray_m;
    ++result->cell_count[cy * kResidualCellsX + cx];
  }
}

// Runs Ceres on one level from *delta; returns false (with a message) when Ceres fails.
bool solveLevel(SdfResiduals* residuals, PriorCost* prior, PriorCost* damping,
                ceres::Manifold* manifold, int max_iterations, double tolerance, Vector6d* delta,
                int* iterations, std::string* message) {
  SdfCost data(residuals);
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  problem.AddResidualBlock(&data, nullptr, delta->data());
  problem.AddResidualBlock(prior, nullptr, delta->data());
  if (damping) problem.AddResidualBlock(damping, nullptr, delta->data());
  if (manifold) problem.SetManifold(delta->data(), manifold);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = max_iterations;
  options.num_threads = 1;  // and so bit-for-bit repeatable
  options.parameter_tolerance = tolerance;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  *iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
  if (summary.termination_type == ceres::FAILURE || !delta->allFinite()) {
    *message = summary.message;
    return false;
  }
  return true;
}

// Ceres's parameter tolerance (step norm relative to the increment's norm) per level. The
// finest level stops at steps of ~0.3 % of the correction (0.1 mm on 3 cm; Ceres's default
// 1e-8 spends the iteration budget chasing noise); coarser levels only need to bring the pose
// into the finest level's basin. Measured on the room frames of the tests: the same errors as
// 1e-3 everywhere with a third fewer iterations.
constexpr double kFineTolerance = 3e-3;
constexpr double kCoarseTolerance = 3e-2;

// Throws Error on input that cannot be a frame at a pose.
void checkInputs(const DepthImage& depth, const PinholeCamera& camera,
                 const Eigen::Isometry3d& T_W_C_prior, double depth_scale_m) {
  std::string why;
  if (!isRigidTransform(T_W_C_prior.matrix(), 1e-6, &why)) {
    throw Error("align: T_W_C_prior is not a rigid transform: " + why);
  }
  if (!camera.isValid(&why)) throw Error("align: invalid camera: " + why);
  if (depth.width() != camera.width || depth.height() != camera.height) {
    throw Error("align: depth image is " + std::to_string(depth.width()) + "x" +
                std::to_string(depth.height()) + " but the camera is " +
                std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  if (!(depth_scale_m > 0.0 && std::isfinite(depth_scale_m))) {
    throw Error("align: depth_scale_m must be positive and finite");
  }
}

std::string format(const char* fmt, double a, double b) {
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer), fmt, a, b);
  return buffer;
}

}  // namespace

const char* alignmentStatusName(AlignmentStatus status) {
  switch (status) {
    case AlignmentStatus::kAccepted:
      return "accepted";
    case AlignmentStatus::kAcceptedPartially:
      return "accepted_partially";
    case AlignmentStatus::kTooFewPoints:
      return "too_few_points";
    case AlignmentStatus::kDegenerate:
      return "degenerate";
    case AlignmentStatus::kLowInlierRatio:
      return "low_inlier_ratio";
    case AlignmentStatus::kCorrectionTooLarge:
      return "correction_too_large";
    case AlignmentStatus::kSolverFailed:
      return "solver_failed";
  }
  return "unknown";
}

void FrameToModelAligner::Config::check() const {
  if (level_strides_px.empty()) throw Error("tracking level_strides_px must not be empty");
  for (int stride : level_strides_px) {
    if (stride < 1) throw Error("tracking level_strides_px must all be >= 1");
  }
  if (max_iterations < 1) throw Error("tracking max_iterations must be >= 1");
  if (!(robust_scale_m > 0.0)) throw Error("tracking robust_scale_m must be > 0");
  if (!(point_sigma_m > 0.0)) throw Error("tracking point_sigma_m must be > 0");
  if (!(depth_noise_at_1m_m >= 0.0 && std::isfinite(depth_noise_at_1m_m))) {
    throw Error("tracking depth_noise_at_1m_m must be >= 0");
  }
  if (!(prior_sigma_translation_m > 0.0)) {
    throw Error("tracking prior_sigma_translation_m must be > 0");
  }
  if (!(prior_sigma_rotation_rad > 0.0)) {
    throw Error("tracking prior_sigma_rotation_rad must be > 0");
  }
  if (!(min_depth_m >= 0.0 && max_depth_m > min_depth_m && std::isfinite(max_depth_m))) {
    throw Error("tracking needs 0 <= min_depth_m < max_depth_m");
  }
  if (min_points < 1) throw Error("tracking min_points must be >= 1");
  if (!(inlier_distance_m > 0.0)) throw Error("tracking inlier_distance_m must be > 0");
  if (!(min_inlier_ratio >= 0.0 && min_inlier_ratio <= 1.0)) {
    throw Error("tracking min_inlier_ratio must be in [0, 1]");
  }
  if (!(weak_direction_damping >= 0.0 && std::isfinite(weak_direction_damping))) {
    throw Error("tracking weak_direction_damping must be >= 0");
  }
  if (!(min_relative_eigenvalue > 0.0 && min_relative_eigenvalue < 1.0)) {
    throw Error("tracking min_relative_eigenvalue must be in (0, 1)");
  }
  if (!(max_correction_translation_m > 0.0)) {
    throw Error("tracking max_correction_translation_m must be > 0");
  }
  if (!(max_correction_rotation_rad > 0.0)) {
    throw Error("tracking max_correction_rotation_rad must be > 0");
  }
}

FrameToModelAligner::Config FrameToModelAligner::Config::forSequences() {
  Config config;
  config.prior_sigma_translation_m = 0.01;
  config.prior_sigma_rotation_rad = 0.01;
  config.weak_direction_damping = 0.01;
  return config;
}

FrameToModelAligner::Config FrameToModelAligner::Config::forDriftFilter() {
  Config config;
  config.level_strides_px = {20, 10};
  return config;
}

FrameToModelAligner::FrameToModelAligner(const Config& config) : config_(config) {
  config_.check();
}

AlignmentResult FrameToModelAligner::align(const TsdfMap& map, const DepthImage& depth,
                                           const PinholeCamera& camera,
                                           const Eigen::Isometry3d& T_W_C_prior,
                                           double depth_scale_m) {
  const auto start = std::chrono::steady_clock::now();
  checkInputs(depth, camera, T_W_C_prior, depth_scale_m);

  AlignmentResult result;
  result.T_W_C = T_W_C_prior;
  auto finish = [&](AlignmentStatus status, std::string reason) {
    result.status = status;
    result.reason = std::move(reason);
    result.accepted =
        status == AlignmentStatus::kAccepted || status == AlignmentStatus::kAcceptedPartially;
    if (result.accepted) {
      result.T_W_C = applyIncrement(T_W_C_prior, result.delta);
    } else {
      result.delta.setZero();
      result.T_W_C = T_W_C_prior;
    }
    ++counts_[static_cast<int>(status)];
    result.time_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
  };
  auto tooFew = [&](int found) {
    return finish(AlignmentStatus::kTooFewPoints,
                  "too few points: " + std::to_string(found) + " in the map, " +
                      std::to_string(config_.min_points) + " needed");
  };

  SdfResidualOptions options;
  options.loss = config_.loss;
  options.robust_scale_m = config_.robust_scale_m;
  options.point_sigma_m = config_.point_sigma_m;
  options.depth_noise_at_1m_m = config_.depth_noise_at_1m_m;
  PriorCost prior(config_.prior_sigma_translation_m, config_.prior_sigma_rotation_rad);

  // The finest level first decides whether there is anything to align.
  const std::vector<Eigen::Vector3f> finest =
      selectPoints(depth, camera, depth_scale_m, config_.level_strides_px.back(),
                   config_.min_depth_m, config_.max_depth_m);
  result.points_selected = static_cast<int>(finest.size());
  if (result.points_selected < config_.min_points || map.numBlocks() == 0) return tooFew(0);

  Vector6d delta = Vector6d::Zero();
  std::string message;
  for (size_t level = 0; level + 1 < config_.level_strides_px.size(); ++level) {
    SdfResiduals residuals(
        map, T_W_C_prior,
        selectPoints(depth, camera, depth_scale_m, config_.level_strides_px[level],
                     config_.min_depth_m, config_.max_depth_m),
        options);
    if (residuals.keepPointsInMap(delta) == 0) continue;
    if (!solveLevel(&residuals, &prior, nullptr, nullptr, config_.max_iterations, kCoarseTolerance,
                    &delta, &result.iterations, &message)) {
      return finish(AlignmentStatus::kSolverFailed, "solver failed: " + message);
    }
  }
  // The points of the finest level are those on the map where the coarser levels left the
  // pose (see SdfResiduals::keepPointsInMap).
  SdfResiduals residuals(map, T_W_C_prior, finest, options);
  result.points_used = residuals.keepPointsInMap(delta);
  if (result.points_used < config_.min_points) return tooFew(result.points_used);
  // Weak-direction damping (Config::weak_direction_damping): a second prior on the increment
  // whose information is the share times the points' strongest eigenvalue, isotropic in the
  // rotation-scaled coordinates of the degeneracy analysis (rotations in metres at the RMS
  // range), measured where the coarser levels left the pose.
  std::unique_ptr<PriorCost> damping;
  if (config_.weak_direction_damping > 0.0) {
    const SdfFitStats shape = residuals.statistics(delta, config_.inlier_distance_m);
    if (shape.points_in_map > 0 && shape.rms_range_m > 0.0) {
      const DegeneracyAnalysis analysis = analyseDegeneracy(shape.normal_matrix, shape.rms_range_m,
                                                            config_.min_relative_eigenvalue);
      const double information = config_.weak_direction_damping * analysis.eigenvalues[5] *
                                 shape.weight_sum / (config_.point_sigma_m * config_.point_sigma_m);
      if (information > 0.0 && std::isfinite(information)) {
        const double sigma_m = 1.0 / std::sqrt(information);
        damping = std::make_unique<PriorCost>(sigma_m, sigma_m / shape.rms_range_m);
      }
    }
  }
  if (!solveLevel(&residuals, &prior, damping.get(), nullptr, config_.max_iterations,
                  kFineTolerance, &delta, &result.iterations, &message)) {
    return finish(AlignmentStatus::kSolverFailed, "solver failed: " + message);
  }

  SdfFitStats stats = residuals.statistics(delta, config_.inlier_distance_m);
  if (stats.points_in_map < config_.min_points) return tooFew(stats.points_in_map);
  const DegeneracyAnalysis analysis =
      analyseDegeneracy(stats.normal_matrix, stats.rms_range_m, config_.min_relative_eigenvalue);
  result.eigenvalues = analysis.eigenvalues;
  result.condition_number = analysis.condition_number;
  result.unconstrained_directions = analysis.unconstrained;
  AlignmentStatus status = AlignmentStatus::kAccepted;
  std::string reason;
  if (analysis.unconstrained > 0) {
    reason = "degenerate: " + std::to_string(analysis.unconstrained) + " unconstrained directions";
    if (!config_.remap_degenerate || analysis.unconstrained == 6) {
      result.solved_delta = delta;
      return finish(AlignmentStatus::kDegenerate, reason);
    }
    // Solution remapping: drop the unconstrained components, then let the constrained ones
    // settle without them.
    delta = analysis.project(delta);
    SubspaceManifold subspace(analysis);
    if (!solveLevel(&residuals, &prior, damping.get(), &subspace, config_.max_iterations,
                    kFineTolerance, &delta, &result.iterations, &message)) {
      return finish(AlignmentStatus::kSolverFailed, "solver failed: " + message);
    }
    stats = residuals.statistics(delta, config_.inlier_distance_m);
    status = AlignmentStatus::kAcceptedPartially;
    reason += ", kept at the prior";
  }
  result.solved_delta = delta;
  result.delta = delta;
  cellResiduals(&residuals, delta, camera, config_.inlier_distance_m, &result);
  {
    Vector6d prior_information;
    prior_information << Eigen::Vector3d::Constant(
        1.0 / (config_.prior_sigma_translation_m * config_.prior_sigma_translation_m)),
        Eigen::Vector3d::Constant(
            1.0 / (config_.prior_sigma_rotation_rad * config_.prior_sigma_rotation_rad));
    result.information =
        stats.normal_matrix * (stats.weight_sum / (config_.point_sigma_m * config_.point_sigma_m));
    result.information.diagonal() += prior_information;
  }
  // Points that slid off the map count against the ratio: a fit that holds on to half of the
  // points by pushing the rest out of the band is no fit.
  result.inlier_ratio = static_cast<double>(stats.inliers) / result.points_used;
  if (stats.points_in_map < config_.min_points) return tooFew(stats.points_in_map);
  if (result.inlier_ratio < config_.min_inlier_ratio) {
    return finish(
        AlignmentStatus::kLowInlierRatio,
        format("low inlier ratio: %.2f < %.2f", result.inlier_ratio, config_.min_inlier_ratio));
  }
  const double translation_m = delta.head<3>().norm(), rotation_rad = delta.tail<3>().norm();
  if (translation_m > config_.max_correction_translation_m ||
      rotation_rad > config_.max_correction_rotation_rad) {
    return finish(AlignmentStatus::kCorrectionTooLarge,
                  format("correction too large: %.3f m, %.3f rad", translation_m, rotation_rad));
  }
  return finish(status, reason);
}

}  // namespace panmap
