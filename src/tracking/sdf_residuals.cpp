#include "panmap/tracking/sdf_residuals.h"

#include <algorithm>
#include <cmath>

namespace panmap {

void robustLoss(RobustLoss loss, double scale_m, double s, double* rho, double* drho) {
  const double b = scale_m * scale_m;
  switch (loss) {
    case RobustLoss::kHuber:
      if (s <= b) {
        *rho = s;
        *drho = 1.0;
      } else {
        const double r = std::sqrt(s);
        *rho = 2.0 * scale_m * r - b;
        *drho = scale_m / r;
      }
      return;
    case RobustLoss::kCauchy:
      *rho = b * std::log1p(s / b);
      *drho = 1.0 / (1.0 + s / b);
      return;
  }
}

SdfResiduals::SdfResiduals(const TsdfMap& map, const Eigen::Isometry3d& T_W_C_prior,
                           const std::vector<Eigen::Vector3f>& points_C,
                           const SdfResidualOptions& options)
    : sampler_(map),
      t_W_C_prior_(T_W_C_prior.translation()),
      R_W_C_prior_(T_W_C_prior.linear()),
      options_(options) {
  rays_W_.reserve(points_C.size());
  inv_scales_.reserve(points_C.size());
  const double relative = options.depth_noise_at_1m_m / options.point_sigma_m;
  for (const Eigen::Vector3f& p_C : points_C) {
    rays_W_.push_back(T_W_C_prior.linear() * p_C.cast<double>());
    const double z = p_C.z(), noise = relative * z * z;
    inv_scales_.push_back(1.0 / std::sqrt(1.0 + noise * noise));
  }
}

int SdfResiduals::evaluate(const Vector6d& delta, double* residuals, double* jacobian) {
  update(delta);
  std::copy(residuals_.begin(), residuals_.end(), residuals);
  if (jacobian) std::copy(jacobian_.begin(), jacobian_.end(), jacobian);
  return in_map_;
}

void SdfResiduals::update(const Vector6d& delta) {
  // Ceres evaluates the residuals at a candidate step and then, once it accepts the step, the
  // Jacobian at the same point; keepPointsInMap() and statistics() ask about that point too.
  // Computing everything once per point halves the TSDF lookups.
  if (valid_ && delta == delta_) return;
  const size_t n = rays_W_.size();
  samples_.assign(n, Sample());
  cells_.resize(n);
  residuals_.assign(n, 0.0);
  jacobian_.assign(6 * n, 0.0);
  const Eigen::Matrix3d R = expSo3(delta.tail<3>());
  const Eigen::Matrix3d J_l = leftJacobianSo3(delta.tail<3>());
  const Eigen::Vector3d t_W = t_W_C_prior_ + delta.head<3>();
  const double inv_sigma = 1.0 / options_.point_sigma_m;
  in_map_ = 0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a_W = R * rays_W_[i];
    Sample& sample = samples_[i];
    sample.in_map =
        sampler_.sample((a_W + t_W).cast<float>(), &sample.sdf_m, &sample.gradient_W, &cells_[i]);
    if (!sample.in_map) continue;
    ++in_map_;
    // In units of a point at the sensor's best depth: the loss and sigma apply to that.
    const double r = sample.sdf_m * inv_scales_[i];
    double rho = 0.0, drho = 0.0;
    robustLoss(options_.loss, options_.robust_scale_m, r * r, &rho, &drho);
    const double root = std::sqrt(rho);
    residuals_[i] = std::copysign(root, r) * inv_sigma;
    // d r' / d r: rho' |r| / sqrt(rho), which tends to 1 at r = 0.
    const double scale = (root > 0.0 ? drho * std::abs(r) / root : 1.0) * inv_sigma;
    const Eigen::Vector3d g_W = sample.gradient_W.cast<double>() * inv_scales_[i];
    // d p_W / d dtheta = -[exp(dtheta) q]x J_l(dtheta), so g^T of that is (a x g)^T J_l.
    const Eigen::Vector3d d_theta = J_l.transpose() * a_W.cross(g_W);
    double* row = &jacobian_[6 * i];
    for (int k = 0; k < 3; ++k) {
      row[k] = scale * g_W[k];
      row[3 + k] = scale * d_theta[k];
    }
  }
  delta_ = delta;
  valid_ = true;
}

int SdfResiduals::keepPointsInMap(const Vector6d& delta) {
  update(delta);
  // Compact the points and their evaluation together: it stays valid at delta.
  size_t kept = 0;
  for (size_t i = 0; i < rays_W_.size(); ++i) {
    if (!samples_[i].in_map) continue;
    rays_W_[kept] = rays_W_[i];
    inv_scales_[kept] = inv_scales_[i];
    samples_[kept] = samples_[i];
    cells_[kept] = cells_[i];
    residuals_[kept] = residuals_[i];
    std::copy_n(&jacobian_[6 * i], 6, &jacobian_[6 * kept]);
    ++kept;
  }
  rays_W_.resize(kept);
  inv_scales_.resize(kept);
  samples_.resize(kept);
  cells_.resize(kept);
  residuals_.resize(kept);
  jacobian_.resize(6 * kept);
  in_map_ = static_cast<int>(kept);
  return in_map_;
}

SdfFitStats SdfResiduals::statistics(const Vector6d& delta, double inlier_distance_m) {
  update(delta);
  SdfFitStats stats;
  const Eigen::Matrix3d R = expSo3(delta.tail<3>());
  double weight_sum = 0.0, range_sq_sum = 0.0;
  Matrix6d H = Matrix6d::Zero();
  for (size_t i = 0; i < rays_W_.size(); ++i) {
    const Sample& sample = samples_[i];
    if (!sample.in_map) continue;
    const Eigen::Vector3d a_W = R * rays_W_[i];
    ++stats.points_in_map;
    stats.inliers += std::abs(sample.sdf_m) <= inlier_distance_m;
    range_sq_sum += a_W.squaredNorm();
    double rho = 0.0, w = 0.0;
    const double r = sample.sdf_m * inv_scales_[i];
    robustLoss(options_.loss, options_.robust_scale_m, r * r, &rho, &w);
    // Tangent (left-perturbation) Jacobian at this pose: J_l drops out at zero increment.
    Vector6d J;
    const Eigen::Vector3d g_W = sample.gradient_W.cast<double>() * inv_scales_[i];
    J << g_W, a_W.cross(g_W);
    H.selfadjointView<Eigen::Upper>().rankUpdate(J, w);
    weight_sum += w;
  }
  if (stats.points_in_map > 0) {
    stats.rms_range_m = std::sqrt(range_sq_sum / stats.points_in_map);
    stats.normal_matrix = H.selfadjointView<Eigen::Upper>();
    stats.normal_matrix /= weight_sum;
    stats.weight_sum = weight_sum;
  }
  return stats;
}

std::vector<SdfResiduals::RayDistance> SdfResiduals::rayDistances(const Vector6d& delta) {
  update(delta);
  const Eigen::Matrix3d R = expSo3(delta.tail<3>());
  std::vector<RayDistance> out;
  out.reserve(static_cast<size_t>(in_map_));
  for (size_t i = 0; i < rays_W_.size(); ++i) {
    const Sample& sample = samples_[i];
    if (!sample.in_map) continue;
    const Eigen::Vector3d a_W = R * rays_W_[i];
    const double norm = a_W.norm() * sample.gradient_W.cast<double>().norm();
    const double cosine =
        norm > 0.0 ? std::abs(a_W.dot(sample.gradient_W.cast<double>())) / norm : 1.0;
    out.push_back({(R_W_C_prior_.transpose() * rays_W_[i]).cast<float>(),
                   static_cast<float>(sample.sdf_m / std::max(cosine, 0.3))});
  }
  return out;
}

}  // namespace panmap
