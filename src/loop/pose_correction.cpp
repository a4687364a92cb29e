#include "panmap/loop/pose_correction.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>

#include "panmap/core/error.h"

namespace panmap {

PoseCorrection keyframeCorrection(const std::vector<StampedPose>& reference, size_t every,
                                  int64_t correction_id, const CorrectionResidual& residual) {
  if (reference.empty()) throw Error("keyframe correction: no reference pose");
  if (every == 0) throw Error("keyframe correction: every must be at least 1");
  if (!(residual.sigma_m >= 0.0) || !(residual.sigma_rad >= 0.0)) {
    throw Error("keyframe correction: residual sigmas must be >= 0");
  }
  std::mt19937_64 rng(residual.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  PoseCorrection correction;
  correction.correction_id = correction_id;
  for (size_t i = 0; i < reference.size(); ++i) {
    if (i % every != 0 && i + 1 != reference.size()) continue;
    StampedPose p = reference[i];
    if (residual.sigma_m > 0.0 || residual.sigma_rad > 0.0) {
      const Eigen::Vector3d t(normal(rng), normal(rng), normal(rng));
      const Eigen::Vector3d r(normal(rng), normal(rng), normal(rng));
      const Eigen::Vector3d w = r * residual.sigma_rad;
      Eigen::Isometry3d E = Eigen::Isometry3d::Identity();
      if (w.norm() > 0.0)
        E.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
      E.translation() = t * residual.sigma_m;
      p.T_W_C = p.T_W_C * E;
    }
    correction.poses.push_back(p);
  }
  correction.utime = reference.back().utime + 1000000;
  return correction;
}

void PoseCorrection::check() const {
  const std::string what = "pose correction " + std::to_string(correction_id);
  if (poses.empty()) throw Error(what + ": no pose");
  // Matching subtracts utimes: beyond 2^61 us (73,000 years) the differences overflow int64.
  constexpr int64_t kMaxUtime = int64_t{1} << 61;
  for (size_t i = 0; i < poses.size(); ++i) {
    const StampedPose& p = poses[i];
    if (p.utime < -kMaxUtime || p.utime > kMaxUtime) {
      throw Error(what + ": utime out of range (" + std::to_string(p.utime) + ")");
    }
    if (i > 0 && p.utime <= poses[i - 1].utime) {
      throw Error(what + ": pose utimes must increase (" + std::to_string(p.utime) + " after " +
                  std::to_string(poses[i - 1].utime) + ")");
    }
    std::string why;
    if (!isRigidTransform(p.T_W_C.matrix(), 1e-6, &why)) {
      throw Error(what + ": pose not rigid (at " + std::to_string(p.utime) + ": " + why + ")");
    }
  }
}

namespace {

// The frame of `trajectory` nearest to utime within tolerance, or -1.
int nearestFrame(const std::vector<StampedPose>& trajectory, int64_t utime, int64_t tolerance) {
  const auto it = std::lower_bound(trajectory.begin(), trajectory.end(), utime,
                                   [](const StampedPose& p, int64_t t) { return p.utime < t; });
  int best = -1;
  int64_t best_gap = tolerance;
  for (auto c : {it, it == trajectory.begin() ? trajectory.end() : it - 1}) {
    if (c == trajectory.end()) continue;
    const int64_t gap = std::abs(c->utime - utime);
    if (gap <= best_gap && (best < 0 || gap < best_gap)) {
      best = static_cast<int>(c - trajectory.begin());
      best_gap = gap;
    }
  }
  return best;
}

// nearestFrame(), and only when the utime is nearer frame k than halfway to its neighbours: a
// frame the mapper dropped lies between two mapped ones, and a wide tolerance gave its
// corrected pose to a neighbour (its pose 200 ms away: a 15 degree turn where 9 were due).
int frameOf(const std::vector<StampedPose>& trajectory, int64_t utime, int64_t tolerance) {
  const int k = nearestFrame(trajectory, utime, tolerance);
  if (k < 0) return -1;
  const int64_t gap = std::abs(trajectory[k].utime - utime);
  if (gap == 0) return k;
  const size_t i = static_cast<size_t>(k);
  if (i > 0 && 2 * gap >= trajectory[i].utime - trajectory[i - 1].utime) return -1;
  if (i + 1 < trajectory.size() && 2 * gap >= trajectory[i + 1].utime - trajectory[i].utime) {
    return -1;
  }
  return k;
}

}  // namespace

CorrectedTrajectory applyCorrection(const std::vector<StampedPose>& trajectory,
                                    const PoseCorrection& correction, int64_t tolerance_us) {
  correction.check();
  for (size_t i = 1; i < trajectory.size(); ++i) {
    if (trajectory[i].utime < trajectory[i - 1].utime) {
      throw Error("trajectory to correct is not sorted by utime");
    }
  }
  CorrectedTrajectory out;
  out.poses = trajectory;
  out.translation_m.assign(trajectory.size(), 0.0);
  out.rotation_rad.assign(trajectory.size(), 0.0);
  // Matched frames in time order with their world-frame correction. Two utimes near one frame
  // (poses come in time order, so they are neighbours here): the nearer takes it.
  std::vector<std::pair<int, Eigen::Isometry3d>> anchors;
  int64_t last_gap = 0;
  int64_t last_utime = 0;
  for (const StampedPose& p : correction.poses) {
    const int k = frameOf(trajectory, p.utime, std::max<int64_t>(tolerance_us, 0));
    const int64_t gap = k < 0 ? 0 : std::abs(trajectory[k].utime - p.utime);
    if (k >= 0 && !anchors.empty() && anchors.back().first == k) {
      if (gap >= last_gap) {
        out.unknown_utimes.push_back(p.utime);
        continue;
      }
      out.unknown_utimes.push_back(last_utime);
      anchors.pop_back();
    }
    if (k < 0) {
      out.unknown_utimes.push_back(p.utime);
      continue;
    }
    anchors.emplace_back(k, p.T_W_C * trajectory[k].T_W_C.inverse());
    last_gap = gap;
    last_utime = p.utime;
  }
  std::sort(out.unknown_utimes.begin(), out.unknown_utimes.end());
  out.matched = static_cast<int>(anchors.size());
  if (anchors.empty()) return out;
  size_t next = 0;  // first anchor at or after frame i
  for (size_t i = 0; i < trajectory.size(); ++i) {
    while (next < anchors.size() && anchors[next].first < static_cast<int>(i)) ++next;
    Eigen::Isometry3d D;
    if (next == anchors.size()) {
      D = anchors.back().second;
    } else if (anchors[next].first == static_cast<int>(i) || next == 0) {
      D = anchors[next].second;
    } else {
      const auto& [a, Da] = anchors[next - 1];
      const auto& [b, Db] = anchors[next];
      const double span = static_cast<double>(trajectory[b].utime - trajectory[a].utime);
      const double s =
          span > 0 ? static_cast<double>(trajectory[i].utime - trajectory[a].utime) / span : 0.0;
      D = interpolatePose(Da, Db, s);
    }
    const Eigen::Isometry3d& before = trajectory[i].T_W_C;
    const Eigen::Isometry3d after = D * before;
    out.poses[i].T_W_C = after;
    out.translation_m[i] = (after.translation() - before.translation()).norm();
    out.rotation_rad[i] = Eigen::AngleAxisd(before.linear().transpose() * after.linear()).angle();
    out.max_translation_m = std::max(out.max_translation_m, out.translation_m[i]);
    out.max_rotation_rad = std::max(out.max_rotation_rad, out.rotation_rad[i]);
  }
  return out;
}

std::string unmatchedCorrectionReason(const std::vector<StampedPose>& trajectory,
                                      const PoseCorrection& correction, int64_t tolerance_us) {
  std::string out =
      "none of its " + std::to_string(correction.poses.size()) + " utimes is a mapped frame";
  if (correction.poses.empty()) return out;
  const int64_t first = correction.poses.front().utime;
  out += " (first " + std::to_string(first);
  if (trajectory.empty()) return out + ", no frame mapped yet)";
  int64_t gap = INT64_MAX;
  for (const StampedPose& p : correction.poses) {
    const int k = nearestFrame(trajectory, p.utime, INT64_MAX);
    if (k >= 0) gap = std::min<int64_t>(gap, std::abs(trajectory[k].utime - p.utime));
  }
  return out + ", " + std::to_string(gap) + " us from the nearest mapped frame, tolerance " +
         std::to_string(std::max<int64_t>(tolerance_us, 0)) + " us)";
}

}  // namespace panmap
