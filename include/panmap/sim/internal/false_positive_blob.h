#pragma once

#include <cmath>

namespace panmap {
namespace internal {
namespace segmenter {

/// The shape of a hallucinated segment: a smooth random blob of radius
/// r0 (1 + a2 cos 2(t - p2) + a3 cos 3(t - p3)) in polar angle t around (cx, cy), pixels.
struct Blob {
  double cx = 0.0, cy = 0.0, r0 = 0.0;
  double c2 = 0.0, s2 = 0.0, c3 = 0.0, s3 = 0.0;  ///< amplitude * cos / sin of the phases
  /// A radius no pixel of the blob lies beyond.
  double reach() const { return r0 * (1.0 + std::hypot(c2, s2) + std::hypot(c3, s3)) + 1.0; }
  /// True when pixel (u, v) is inside. Multiple-angle formulas instead of trigonometry: this is
  /// asked for every pixel around the blob.
  bool contains(double u, double v) const {
    const double x = u - cx;
    const double y = v - cy;
    const double rr = x * x + y * y;
    if (rr < 1e-9) return true;
    const double r = std::sqrt(rr);
    const double c = x / r;
    const double s = y / r;
    const double cos2 = c * c - s * s, sin2 = 2.0 * c * s;
    const double cos3 = 4.0 * c * c * c - 3.0 * c, sin3 = 3.0 * s - 4.0 * s * s * s;
    const double f = 1.0 + c2 * cos2 + s2 * sin2 + c3 * cos3 + s3 * sin3;
    return r < r0 * f;
  }
};

}  // namespace segmenter
}  // namespace internal
}  // namespace panmap
