#pragma once

namespace panmap {
namespace internal {

/// Where a continuous grid coordinate g falls between the values of a row of n: the lower index,
/// the upper one and the upper one's weight. Outside [0, n - 1] the end value holds.
struct GridLerp {
  int i0 = 0, i1 = 0;
  double t = 0.0;
};

/// GridLerp of g over n values.
inline GridLerp gridLerp(double g, int n) {
  GridLerp l;
  if (!(g > 0.0)) return l;  // also NaN
  if (g >= n - 1) {
    l.i0 = l.i1 = n - 1;
    return l;
  }
  l.i0 = static_cast<int>(g);
  l.i1 = l.i0 + 1;
  l.t = g - l.i0;
  return l;
}

/// The grid coordinates of a depth calibration: image cells with their centres at (i + 0.5)
/// cell sizes, depth knots at multiples of the spacing.
inline GridLerp cellLerp(double pixel, int image_size, int cells) {
  return gridLerp(pixel / image_size * cells - 0.5, cells);
}
/// @copydoc cellLerp
inline GridLerp knotLerp(double z_m, double inverse_spacing_per_m, int knots) {
  return gridLerp(z_m * inverse_spacing_per_m, knots);
}

}  // namespace internal
}  // namespace panmap
