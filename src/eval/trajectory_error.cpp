#include "panmap/eval/trajectory_error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <tuple>

#include <Eigen/Geometry>

#include "panmap/core/error.h"

namespace panmap {

void TrajectoryErrorConfig::check() const {
  if (!(max_time_difference_s >= 0.0 && max_time_difference_s < 1e6)) {
    throw Error("max_time_difference_s must be in [0, 1e6) seconds");
  }
  if (!(rpe_delta_s > 0.0 && rpe_delta_s < 1e6)) {
    throw Error("rpe_delta_s must be in (0, 1e6) seconds");
  }
}

ErrorStats errorStats(std::vector<double> errors) {
  ErrorStats s;
  s.count = errors.size();
  if (errors.empty()) return s;
  double sum = 0.0, sum_sq = 0.0;
  for (double e : errors) {
    sum += e;
    sum_sq += e * e;
    s.max = std::max(s.max, e);
  }
  const double n = static_cast<double>(errors.size());
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  std::sort(errors.begin(), errors.end());
  const size_t mid = errors.size() / 2;
  s.median = errors.size() % 2 ? errors[mid] : 0.5 * (errors[mid - 1] + errors[mid]);
  return s;
}

std::vector<std::pair<size_t, size_t>> associateByTime(const std::vector<StampedPose>& estimate,
                                                       const std::vector<StampedPose>& ground_truth,
                                                       int64_t max_difference_us) {
  // Ground truth by time, for a window search per estimated pose.
  std::vector<size_t> gt_order(ground_truth.size());
  std::iota(gt_order.begin(), gt_order.end(), 0);
  std::stable_sort(gt_order.begin(), gt_order.end(), [&](size_t a, size_t b) {
    return ground_truth[a].utime < ground_truth[b].utime;
  });
  // (|dt|, estimate stamp, gt stamp, estimate, gt): ties go to the earlier stamps, whatever
  // the input order.
  std::vector<std::tuple<int64_t, int64_t, int64_t, size_t, size_t>> candidates;
  for (size_t i = 0; i < estimate.size(); ++i) {
    const int64_t t = estimate[i].utime;
    auto it =
        std::lower_bound(gt_order.begin(), gt_order.end(), t - max_difference_us,
                         [&](size_t g, int64_t value) { return ground_truth[g].utime < value; });
    for (; it != gt_order.end() && ground_truth[*it].utime <= t + max_difference_us; ++it) {
      candidates.emplace_back(std::abs(ground_truth[*it].utime - t), t, ground_truth[*it].utime, i,
                              *it);
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<bool> used_estimate(estimate.size(), false), used_gt(ground_truth.size(), false);
  std::vector<std::pair<size_t, size_t>> pairs;
  for (const auto& [dt, t_estimate, t_gt, i, g] : candidates) {
    if (used_estimate[i] || used_gt[g]) continue;
    used_estimate[i] = used_gt[g] = true;
    pairs.emplace_back(i, g);
  }
  std::sort(pairs.begin(), pairs.end(), [&](const auto& a, const auto& b) {
    return std::tie(estimate[a.first].utime, a.first) < std::tie(estimate[b.first].utime, b.first);
  });
  return pairs;
}

TrajectoryAlignment fitAlignment(const std::vector<Eigen::Matrix3d>& R_est,
                                 const Eigen::Matrix3Xd& p_est, const Eigen::Matrix3Xd& p_gt,
                                 bool fit_scale, bool fit_camera_offset) {
  const Eigen::Index n = p_est.cols();
  const Eigen::Matrix4d similarity = Eigen::umeyama(p_est, p_gt, fit_scale);
  TrajectoryAlignment a;
  a.scale = fit_scale ? similarity.block<3, 1>(0, 0).norm() : 1.0;
  a.T.linear() = similarity.block<3, 3>(0, 0) / a.scale;
  a.T.translation() = similarity.block<3, 1>(0, 3);
  if (!fit_camera_offset) return a;
  // Gauss-Newton over (rotation as a left increment, translation, d, log scale):
  // r_k = s R (p_k + R_k d) + t - q_k is linear in t and d, so the steps converge fast.
  for (int iteration = 0; iteration < 100; ++iteration) {
    Eigen::Matrix<double, 10, 10> JtJ = Eigen::Matrix<double, 10, 10>::Zero();
    Eigen::Matrix<double, 10, 1> Jtr = Eigen::Matrix<double, 10, 1>::Zero();
    for (Eigen::Index k = 0; k < n; ++k) {
      const Eigen::Vector3d moved =
          a.scale * (a.T.linear() * (p_est.col(k) + R_est[k] * a.camera_offset));
      const Eigen::Vector3d r = moved + a.T.translation() - p_gt.col(k);
      Eigen::Matrix<double, 3, 10> J;
      J << -skew(moved), Eigen::Matrix3d::Identity(), a.scale * a.T.linear() * R_est[k],
          fit_scale ? moved : Eigen::Vector3d::Zero();
      JtJ += J.transpose() * J;
      Jtr += J.transpose() * r;
    }
    const Eigen::Matrix<double, 10, 1> step = -JtJ.completeOrthogonalDecomposition().solve(Jtr);
    const Eigen::Vector3d omega = step.head<3>();
    if (omega.norm() > 0.0) {
      a.T.linear() = Eigen::AngleAxisd(omega.norm(), omega.normalized()).matrix() * a.T.linear();
    }
    a.T.translation() += step.segment<3>(3);
    a.camera_offset += step.segment<3>(6);
    a.scale *= std::exp(step(9));
    if (step.norm() < 1e-14) break;
  }
  return a;
}

TrajectoryError evaluateTrajectory(const std::vector<StampedPose>& estimate,
                                   const std::vector<StampedPose>& ground_truth,
                                   const TrajectoryErrorConfig& config) {
  config.check();
  const int64_t tolerance_us = std::llround(config.max_time_difference_s * 1e6);
  const auto pairs = associateByTime(estimate, ground_truth, tolerance_us);
  TrajectoryError out;
  out.num_estimated = estimate.size();
  out.num_ground_truth = ground_truth.size();
  out.num_associated = pairs.size();
  out.rpe_delta_s = config.rpe_delta_s;
  if (pairs.size() < 3) {
    throw Error("only " + std::to_string(pairs.size()) +
                " estimated poses have a ground-truth pose within " +
                std::to_string(config.max_time_difference_s) + " s (need 3)");
  }

  // ATE (Sturm et al. 2012, Eq. 3-4): Horn's closed form via Umeyama without scale.
  const Eigen::Index n = static_cast<Eigen::Index>(pairs.size());
  Eigen::Matrix3Xd p_est(3, n), p_gt(3, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    p_est.col(k) = estimate[pairs[k].first].T_W_C.translation();
    p_gt.col(k) = ground_truth[pairs[k].second].T_W_C.translation();
  }
  std::vector<Eigen::Matrix3d> R_est(pairs.size());
  for (Eigen::Index k = 0; k < n; ++k) R_est[k] = estimate[pairs[k].first].T_W_C.linear();
  const TrajectoryAlignment alignment =
      fitAlignment(R_est, p_est, p_gt, config.fit_scale, config.fit_camera_offset);
  out.T_gt_est = alignment.T;
  out.scale = alignment.scale;
  out.camera_offset_m = alignment.camera_offset;
  std::vector<double> ate(pairs.size());
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Vector3d p = p_est.col(k) + R_est[k] * out.camera_offset_m;
    ate[k] = (out.T_gt_est * (out.scale * p) - p_gt.col(k)).norm();
  }
  out.ate_m = errorStats(std::move(ate));

  // RPE (Sturm et al. 2012, Eq. 1-2) over a fixed time delta.
  const int64_t delta_us = std::llround(config.rpe_delta_s * 1e6);
  std::vector<double> rpe_m, rpe_deg;
  for (size_t a = 0; a < pairs.size(); ++a) {
    const int64_t target = estimate[pairs[a].first].utime + delta_us;
    // Pairs are sorted by estimate time: the nearest stamp is at the lower bound or before it.
    auto it = std::lower_bound(
        pairs.begin(), pairs.end(), target,
        [&](const auto& p, int64_t value) { return estimate[p.first].utime < value; });
    size_t b = static_cast<size_t>(it - pairs.begin());
    if (b == pairs.size() || (b > 0 && target - estimate[pairs[b - 1].first].utime <
                                           estimate[pairs[b].first].utime - target)) {
      b = b - 1;
    }
    if (b <= a || std::abs(estimate[pairs[b].first].utime - target) > tolerance_us) continue;
    const Eigen::Isometry3d& P_i = estimate[pairs[a].first].T_W_C;
    const Eigen::Isometry3d& P_j = estimate[pairs[b].first].T_W_C;
    const Eigen::Isometry3d& Q_i = ground_truth[pairs[a].second].T_W_C;
    const Eigen::Isometry3d& Q_j = ground_truth[pairs[b].second].T_W_C;
    const Eigen::Isometry3d E = (Q_i.inverse() * Q_j).inverse() * (P_i.inverse() * P_j);
    rpe_m.push_back(E.translation().norm());
    // AngleAxis goes through a quaternion: accurate for small angles, unlike acos of the trace.
    rpe_deg.push_back(Eigen::AngleAxisd(E.linear()).angle() * 180.0 / M_PI);
  }
  out.rpe_m = errorStats(std::move(rpe_m));
  out.rpe_deg = errorStats(std::move(rpe_deg));
  return out;
}

std::string formatTrajectoryError(const TrajectoryError& e) {
  char line[256];
  std::string out;
  std::snprintf(line, sizeof(line),
                "trajectory: %zu estimated, %zu ground-truth, %zu associated poses\n",
                e.num_estimated, e.num_ground_truth, e.num_associated);
  out += line;
  auto row = [&](const char* name, const ErrorStats& s) {
    if (s.count == 0) {
      std::snprintf(line, sizeof(line), "%-18s -  (no pose pairs)\n", name);
    } else {
      std::snprintf(line, sizeof(line),
                    "%-18s rmse %.4f  mean %.4f  median %.4f  max %.4f  (n=%zu)\n", name, s.rmse,
                    s.mean, s.median, s.max, s.count);
    }
    out += line;
  };
  row("ATE [m]", e.ate_m);
  if (e.scale != 1.0) {
    std::snprintf(line, sizeof(line), "scale             %.5f  (fitted)\n", e.scale);
    out += line;
  }
  if (!e.camera_offset_m.isZero()) {
    std::snprintf(line, sizeof(line), "camera offset [m] %.4f %.4f %.4f  (|d| %.4f, fitted)\n",
                  e.camera_offset_m.x(), e.camera_offset_m.y(), e.camera_offset_m.z(),
                  e.camera_offset_m.norm());
    out += line;
  }
  std::snprintf(line, sizeof(line), "RPE over %g s:\n", e.rpe_delta_s);
  out += line;
  row("  translation [m]", e.rpe_m);
  row("  rotation [deg]", e.rpe_deg);
  return out;
}

}  // namespace panmap
