#pragma once

#include <string>

#include <Eigen/Core>

namespace panmap {

/// Pinhole camera in the optical convention (x right, y down, z forward); pixel (0, 0) is the
/// centre of the top-left pixel.
struct PinholeCamera {
  double fx = 0.0;  ///< focal length along x, pixels
  double fy = 0.0;  ///< focal length along y, pixels
  double cx = 0.0;  ///< principal point x, pixels
  double cy = 0.0;  ///< principal point y, pixels
  int width = 0;    ///< image width, pixels
  int height = 0;   ///< image height, pixels

  /// True when focal lengths are positive and finite and the image size is positive.
  /// @param why if not null, receives the reason on failure.
  bool isValid(std::string* why = nullptr) const;

  /// Point in the camera frame seen at pixel (u, v) at depth z_m (metres along the optical axis).
  Eigen::Vector3d backProject(double u, double v, double z_m) const {
    return Eigen::Vector3d((u - cx) * z_m / fx, (v - cy) * z_m / fy, z_m);
  }

  /// Pixel of a camera-frame point; false when it is behind the camera.
  bool project(const Eigen::Vector3d& p_C, Eigen::Vector2d* uv) const {
    if (p_C.z() <= 0.0) return false;
    *uv = Eigen::Vector2d(fx * p_C.x() / p_C.z() + cx, fy * p_C.y() / p_C.z() + cy);
    return true;
  }

  /// The same camera seen through an image resized to new_width x new_height (pixel-centre
  /// convention: a pixel's centre maps to the centre of the corresponding resized pixel).
  PinholeCamera resized(int new_width, int new_height) const;
};

}  // namespace panmap
