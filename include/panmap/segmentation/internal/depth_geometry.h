#pragma once

#include <cstdint>
#include <vector>

#include "panmap/core/frame.h"

namespace panmap {
namespace internal {

/// Camera-frame points, depth discontinuities and normals of one depth image, one float plane
/// per component (structure of arrays, row-major) so the per-row loops vectorise.
struct DepthGeometry {
  int width = 0;
  int height = 0;
  std::vector<float> x_m, y_m, z_m;  ///< point; all 0 where the depth is invalid
  std::vector<float> discontinuity;  ///< 1 where a valid pixel's depth jumps to a neighbour
  std::vector<float> surface_step;   ///< 1 where it jumps by twice that to a valid neighbour
  std::vector<float> nx, ny, nz;     ///< unit normal toward the camera; all 0 where none
  std::vector<float> has_normal;     ///< 1 where the pixel has a normal, else 0

  /// Sizes every plane to width x height (no reallocation when the size is unchanged).
  void resize(int width, int height);
  /// Index of pixel (u, v) in the planes.
  size_t index(int u, int v) const { return static_cast<size_t>(v) * width + u; }
};

/// Back-projects rows [v0, v1) of the frame's depth into `geometry`; depth beyond
/// max_depth_m counts as invalid. `geometry` must be sized to the frame.
void backProjectRows(const RgbdFrame& frame, float max_depth_m, int v0, int v1,
                     DepthGeometry* geometry);

/// Marks rows [v0, v1) of geometry->discontinuity: a valid pixel whose depth differs from
/// an 8-neighbour's by more than ratio * its own depth (an invalid neighbour always does, as
/// in the released code); and of geometry->surface_step: a jump of twice that to a valid
/// neighbour, which marks another surface rather than noise or a hole.
/// Reads the points of rows v0 - 1 to v1.
void markDiscontinuityRows(float ratio, int v0, int v1, DepthGeometry* geometry);

/// Surface normals from box sums over the point planes: one estimator per thread, holding
/// its running sums so a frame allocates nothing once the sizes are known.
class NormalEstimator {
 public:
  /// Normals of rows [v0, v1), reading points and discontinuities of the rows within
  /// window_px / 2 of the band.
  /// @param window_px odd side of the square neighbourhood, pixels
  void computeRows(int window_px, int v0, int v1, DepthGeometry* geometry);

 private:
  size_t paddedWidth(int width) const { return static_cast<size_t>(width) + 2 * r_; }
  void sumColumns(const DepthGeometry& g, int v_begin, int v_end, float* columns) const;
  void addRow(const DepthGeometry& g, int v, float sign, float* columns) const;
  void windowSums(const float* columns, int channels, int width, float* out);
  void normalsOfRow(int v, DepthGeometry* g);

  // Column arrays are padded with r zero columns on each side (width + 2r per channel), so
  // window sums clip to the image without branches; window arrays hold width + r sums.
  int r_ = 0;                         ///< window radius, pixels
  std::vector<float> top_;            ///< per channel, padded column: sums of rows [v - r, v]
  std::vector<float> bottom_;         ///< per channel, padded column: sums of rows [v, v + r]
  std::vector<float> window_top_;     ///< per channel: top_ summed over columns [k - r, k]
  std::vector<float> window_bottom_;  ///< per channel: bottom_ summed likewise
  std::vector<float> row_;            ///< x, y, z, valid of row v, padded
  std::vector<float> row_window_;     ///< row_ summed over columns [k - r, k]
  std::vector<float> powers_;         ///< sums of 2^b consecutive columns, per b
  std::vector<float> cols_left_;      ///< per column: columns of [u - r, u] in the image
  std::vector<float> cols_right_;     ///< per column: columns of [u, u + r] in the image
  std::vector<float> inv_cols_left_;  ///< their reciprocals
  std::vector<float> inv_cols_right_;
};

}  // namespace internal
}  // namespace panmap
