#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "panmap/map/tsdf_map.h"
#include "panmap/tracking/pose_increment.h"
#include "panmap/tracking/sdf_sampler.h"

namespace panmap {

/// Robust loss on a squared residual.
enum class RobustLoss {
  kHuber,   ///< quadratic inside the scale, linear outside
  kCauchy,  ///< logarithmic: far outliers barely count
};

/// rho(s) and rho'(s) of a loss for a squared residual s (m^2) at a scale (m), Ceres's
/// convention (rho(s) = s and rho'(s) = 1 near 0).
void robustLoss(RobustLoss loss, double scale_m, double s, double* rho, double* drho);

/// How SdfResiduals weighs the points.
struct SdfResidualOptions {
  RobustLoss loss = RobustLoss::kHuber;
  double robust_scale_m = 0.01;  ///< loss scale, metres
  double point_sigma_m = 0.01;   ///< residuals are divided by this (information vs the prior)
  /// Depth noise of the sensor at 1 m, metres; it grows with the square of the depth (structured
  /// light and stereo: disparity noise), and a point at depth z counts as
  /// sqrt(point_sigma^2 + (depth_noise_at_1m z^2)^2) / point_sigma times point_sigma_m, loss
  /// scale included. 0 = every point alike.
  double depth_noise_at_1m_m = 0.0;
};

/// What the points say at one pose increment.
struct SdfFitStats {
  int points_in_map = 0;     ///< points whose 8 surrounding voxels are all observed
  int inliers = 0;           ///< of those, |sdf| <= the inlier distance
  double rms_range_m = 0.0;  ///< RMS distance of the in-map points from the camera centre
  /// Robust-weighted sum of J^T J over the in-map points, divided by the sum of the weights
  /// (J = d sdf / d increment at the increment, without the point sigma): the shape of the
  /// information, for the degeneracy check.
  Matrix6d normal_matrix = Matrix6d::Zero();
  /// Sum of the robust weights (rho') of the in-map points: normal_matrix * weight_sum /
  /// point_sigma^2 is the Gauss-Newton information of the points.
  double weight_sum = 0.0;
};

/// Point-to-model residuals of a frame's depth points against the TSDF zero crossing: the
/// residual of a point is the interpolated signed distance at its world position (the
/// gradient of the TSDF is the surface normal, so this is a point-to-plane distance), as a
/// function of a pose increment (pose_increment.h) applied to the prior pose.
///
/// The robust loss is folded into each residual so that a single Ceres cost function can
/// carry all points: r' = sign(r) sqrt(rho(r^2)) / sigma, so that sum r'^2 / 2 is exactly the
/// robust cost and J'^T r' exactly its gradient (only the Gauss-Newton curvature of the
/// outliers is approximated).
///
/// A point whose neighbourhood is unobserved has residual 0 and no gradient. The alternative,
/// a constant cost such as the truncation distance, was measured to bias weakly constrained
/// directions by millimetres: a single point stepping onto the map's edge outweighs the whole
/// fit there. With 0, a point leaving the map gives up only its (near zero) residual.
class SdfResiduals {
 public:
  /// @param T_W_C_prior camera-to-world pose the increments apply to
  /// @param points_C depth points, camera frame, metres
  SdfResiduals(const TsdfMap& map, const Eigen::Isometry3d& T_W_C_prior,
               const std::vector<Eigen::Vector3f>& points_C, const SdfResidualOptions& options);

  /// Number of residuals (one per point).
  int size() const { return static_cast<int>(rays_W_.size()); }

  /// Residuals and, if jacobian is not null, their row-major size() x 6 Jacobian with
  /// respect to the increment, at `delta`. Returns the number of points inside the map.
  int evaluate(const Vector6d& delta, double* residuals, double* jacobian);

  /// Keeps only the points inside the observed map at `delta` and returns how many remain.
  /// Residuals are then taken over a fixed set: a point that was off the map never pulls
  /// the pose to bring it onto the map (which would bias the pose toward the explored part).
  int keepPointsInMap(const Vector6d& delta);

  /// In-map points, inliers, range and normal matrix at `delta`.
  /// @param inlier_distance_m an in-map point with |sdf| at most this is an inlier
  SdfFitStats statistics(const Vector6d& delta, double inlier_distance_m);

  /// One in-map point at an increment: where it is in the prior's camera frame, and its
  /// distance to the surface along its ray (signed distance over the cosine between ray and
  /// normal, clamped at 0.3: positive when the point reads short, in front of the surface).
  struct RayDistance {
    Eigen::Vector3f p_C;
    float along_ray_m;
  };
  /// The in-map points' distances along their rays at `delta`.
  std::vector<RayDistance> rayDistances(const Vector6d& delta);

 private:
  struct Sample {
    bool in_map = false;
    float sdf_m = 0.0f;
    Eigen::Vector3f gradient_W = Eigen::Vector3f::Zero();
  };
  void update(const Vector6d& delta);  // evaluates every point at delta unless already done

  SdfSampler sampler_;
  Eigen::Vector3d t_W_C_prior_;
  Eigen::Matrix3d R_W_C_prior_;
  std::vector<Eigen::Vector3d> rays_W_;  // R_W_C_prior p_C: the points about the camera centre
  std::vector<double> inv_scales_;       // point_sigma / the point's sigma (depth noise)
  SdfResidualOptions options_;
  // The evaluation at delta_ (when valid_): samples, residuals, row-major Jacobian.
  bool valid_ = false;
  Vector6d delta_ = Vector6d::Zero();
  int in_map_ = 0;
  std::vector<Sample> samples_;
  std::vector<SdfSampler::Cell> cells_;  // each point's voxels, kept across evaluations
  std::vector<double> residuals_;
  std::vector<double> jacobian_;
};

}  // namespace panmap
