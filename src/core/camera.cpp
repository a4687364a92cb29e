#include "panmap/core/camera.h"

#include <cmath>
#include <sstream>

namespace panmap {

bool PinholeCamera::isValid(std::string* why) const {
  std::ostringstream reason;
  if (!(std::isfinite(fx) && std::isfinite(fy) && fx > 0.0 && fy > 0.0)) {
    reason << "focal lengths must be positive and finite (fx " << fx << ", fy " << fy << ")";
  } else if (!(std::isfinite(cx) && std::isfinite(cy))) {
    reason << "principal point must be finite";
  } else if (width <= 0 || height <= 0) {
    reason << "image size must be positive (" << width << "x" << height << ")";
  } else {
    return true;
  }
  if (why) *why = reason.str();
  return false;
}

PinholeCamera PinholeCamera::resized(int new_width, int new_height) const {
  // Pixel centres: u' + 0.5 = (u + 0.5) * s, so cx' = (cx + 0.5) * s - 0.5.
  const double sx = static_cast<double>(new_width) / width;
  const double sy = static_cast<double>(new_height) / height;
  PinholeCamera out;
  out.fx = fx * sx;
  out.fy = fy * sy;
  out.cx = (cx + 0.5) * sx - 0.5;
  out.cy = (cy + 0.5) * sy - 0.5;
  out.width = new_width;
  out.height = new_height;
  return out;
}

}  // namespace panmap
