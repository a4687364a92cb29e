#include "panmap/core/pose.h"

#include <cmath>
#include <sstream>

#include <Eigen/SVD>

namespace panmap {

bool isRigidTransform(const Eigen::Matrix4d& T, double tolerance, std::string* why) {
  std::ostringstream reason;
  if (!T.allFinite()) {
    reason << "non-finite entry (nan or inf)";
  } else if (std::abs(T(3, 0)) > tolerance || std::abs(T(3, 1)) > tolerance ||
             std::abs(T(3, 2)) > tolerance || std::abs(T(3, 3) - 1.0) > tolerance) {
    reason << "last row is not 0 0 0 1";
  } else {
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    const double ortho_error =
        (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (ortho_error > tolerance) {
      reason << "rotation is not orthonormal (error " << ortho_error << ")";
    } else if (R.determinant() < 0.0) {
      reason << "rotation is a reflection (determinant < 0)";
    } else {
      return true;
    }
  }
  if (why) *why = reason.str();
  return false;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

Eigen::Isometry3d nearestIsometry(const Eigen::Matrix4d& T) {
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = svd.matrixU() * D * svd.matrixV().transpose();
  out.translation() = T.topRightCorner<3, 1>();
  return out;
}

Eigen::Isometry3d interpolatePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                                  double t) {
  const Eigen::Quaterniond qa(a.linear());
  const Eigen::Quaterniond qb(b.linear());
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = qa.slerp(t, qb).normalized().toRotationMatrix();
  out.translation() = (1.0 - t) * a.translation() + t * b.translation();
  return out;
}

const char* poseSourceName(PoseSource source) {
  switch (source) {
    case PoseSource::kGroundTruth:
      return "ground_truth";
    case PoseSource::kSlam:
      return "slam";
    case PoseSource::kOdometry:
      return "odometry";
    default:
      return "unknown";
  }
}

}  // namespace panmap
