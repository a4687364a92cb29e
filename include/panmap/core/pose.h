#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Geometry>

namespace panmap {

/// Who estimated a camera pose; drift correction trusts ground truth and refines the others.
enum class PoseSource : int8_t {
  kUnknown = 0,
  kGroundTruth = 1,
  kSlam = 2,
  kOdometry = 3,
};

/// Camera pose T_W_C (camera to world) at time utime.
struct StampedPose {
  int64_t utime = 0;      ///< microseconds
  int64_t frame_id = -1;  ///< frame the pose belongs to, -1 if none
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  PoseSource source = PoseSource::kUnknown;
};

/// Checks that a 4x4 matrix is a rigid transform: all finite, last row 0 0 0 1, rotation
/// orthonormal with determinant +1 within `tolerance` (max abs entry of R^T R - I).
/// @param why if not null, receives a short reason on failure.
bool isRigidTransform(const Eigen::Matrix4d& T, double tolerance, std::string* why = nullptr);

/// The rigid transform nearest to T (rotation projected onto SO(3) by SVD).
Eigen::Isometry3d nearestIsometry(const Eigen::Matrix4d& T);

/// Pose between two stamped poses: linear in translation, slerp in rotation.
/// @param t in [0, 1]: 0 gives a, 1 gives b.
Eigen::Isometry3d interpolatePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double t);

/// The cross-product matrix [v]x: skew(v) * w = v.cross(w).
Eigen::Matrix3d skew(const Eigen::Vector3d& v);

/// Name of a pose source ("ground_truth", "slam", ...).
const char* poseSourceName(PoseSource source);

}  // namespace panmap
