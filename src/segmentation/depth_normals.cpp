// Depth -> camera-frame points -> depth discontinuities and surface normals from box sums
// (paper III-A, the first steps of the geometric segmentation).
#include <algorithm>
#include <cmath>
#include <cstring>

#include "panmap/segmentation/internal/depth_geometry.h"
#include "panmap/core/vector_clones.h"

namespace panmap {
namespace internal {

namespace {

// Box channels: sums of x, y, z, and of a per-pixel "usable" value: 1 for a valid pixel,
// minus kStepWeight for a surface step. A box sum of it equals the box's valid count when the
// box holds no step and is negative otherwise, so one channel answers both questions. Float
// sums of these whole numbers are exact while below 2^24: kStepWeight x the largest quadrant
// (64 x 64 for the largest window check() allows).
constexpr int kChannels = 4;
constexpr int kX = 0, kY = 1, kZ = 2, kUsable = 3;
constexpr float kStepWeight = 4096.0f;
// The centre row's channels: x, y, z, valid (in the kUsable slot, without steps).
constexpr int kRowChannels = 4;
// A quadrant with fewer valid pixels than this fraction of its area has too few to average.
constexpr float kMinValidFraction = 0.5f;
// A surface step (which keeps a quadrant out of a normal) is a jump of this many times the
// discontinuity ratio: such jumps come from another surface. Smaller ones are mostly depth
// quantisation along slanted surfaces (structured-light sensors step by ~0.3% of z per metre
// of range), and gating on them would leave most windows of a slanted floor without usable
// quadrants (on 7-Scenes frame 0: 69% of valid pixels in segments, against 46%).
constexpr float kSurfaceStepFactor = 2.0f;
// Running column sums are float; recomputing them every so many rows bounds the drift.
constexpr int kResyncRows = 32;
// Spans closer to parallel than this (sine of their angle) give no reliable normal.
constexpr float kMinSpanSine = 1e-3f;
// Depths at or below this are invalid (0 marks them).
constexpr float kMinDepthM = 1e-6f;
// Keeps empty weights finite without a select: a select before a division lets the compiler
// move the division into a branch, which stops vectorisation.
constexpr float kTiny = 1e-20f;

// 1 when x < 0 (or a non-negative whole count is 0), else 0, without a comparison: the
// compiler turns a comparison feeding arithmetic into branches (per outcome), which stops
// vectorisation.
inline float isNegative(float x) {
  uint32_t bits;
  std::memcpy(&bits, &x, sizeof(bits));
  return static_cast<float>(bits >> 31);
}
inline float isZero(float count) { return isNegative(count - 0.5f); }

// 1 / sqrt(x) for x > 0 to float precision, from the classic bit-level first guess and three
// Newton steps (relative error 3e-2, 1e-3, 2e-6, then rounding). std::sqrt may set errno,
// which keeps a loop from vectorising.
inline float inverseSqrt(float x) {
  uint32_t bits;
  std::memcpy(&bits, &x, sizeof(bits));
  bits = 0x5f3759dfu - (bits >> 1);
  float y;
  std::memcpy(&y, &bits, sizeof(y));
  for (int step = 0; step < 3; ++step) y *= 1.5f - 0.5f * x * y * y;
  return y;
}

}  // namespace

void DepthGeometry::resize(int new_width, int new_height) {
  width = new_width;
  height = new_height;
  const size_t n = static_cast<size_t>(new_width) * new_height;
  for (std::vector<float>* plane :
       {&x_m, &y_m, &z_m, &discontinuity, &surface_step, &nx, &ny, &nz, &has_normal}) {
    plane->resize(n);
  }
}

PANMAP_VECTOR_CLONES
void backProjectRows(const RgbdFrame& frame, float max_depth_m, int v0, int v1,
                     DepthGeometry* geometry) {
  const PinholeCamera& camera = frame.camera;
  const int width = geometry->width;
  const float scale_m = static_cast<float>(frame.depth_scale_m);
  const float inv_fx = static_cast<float>(1.0 / camera.fx);
  const float cx = static_cast<float>(camera.cx);
  for (int v = v0; v < v1; ++v) {
    const uint16_t* depth = frame.depth.row(v);
    const size_t row = geometry->index(0, v);
    float* __restrict x = geometry->x_m.data() + row;
    float* __restrict y = geometry->y_m.data() + row;
    float* __restrict z = geometry->z_m.data() + row;
    const float ray_y = static_cast<float>((v - camera.cy) / camera.fy);
    for (int u = 0; u < width; ++u) {
      float z_m = static_cast<float>(depth[u]) * scale_m;
      z_m = z_m <= max_depth_m ? z_m : 0.0f;
      z[u] = z_m;
      x[u] = (static_cast<float>(u) - cx) * inv_fx * z_m;
      y[u] = ray_y * z_m;
    }
  }
}

PANMAP_VECTOR_CLONES
void markDiscontinuityRows(float ratio, int v0, int v1, DepthGeometry* geometry) {
  DepthGeometry& g = *geometry;
  const float step_ratio = kSurfaceStepFactor * ratio;
  const int width = g.width;
  for (int v = v0; v < v1; ++v) {
    const float* __restrict z = g.z_m.data() + g.index(0, v);
    // The largest depth difference to any neighbour, and to a valid one, kept in the output
    // rows until they are thresholded.
    float* __restrict jump = g.discontinuity.data() + g.index(0, v);
    float* __restrict step = g.surface_step.data() + g.index(0, v);
    std::fill_n(jump, width, 0.0f);
    std::fill_n(step, width, 0.0f);
    for (int dy = -1; dy <= 1; ++dy) {
      if (v + dy < 0 || v + dy >= g.height) continue;
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0) continue;
        const float* __restrict zn = g.z_m.data() + g.index(0, v + dy) + dx;
        const int u_begin = std::max(0, -dx);
        const int u_end = std::min(width, width - dx);
#pragma GCC ivdep
        for (int u = u_begin; u < u_end; ++u) {
          const float difference = std::fabs(zn[u] - z[u]);
          const float to_valid = zn[u] > 0.0f ? difference : 0.0f;
          jump[u] = difference > jump[u] ? difference : jump[u];
          step[u] = to_valid > step[u] ? to_valid : step[u];
        }
      }
    }
#pragma GCC ivdep
    for (int u = 0; u < width; ++u) {
      const bool valid = z[u] > 0.0f;
      jump[u] = valid & (jump[u] > ratio * z[u]) ? 1.0f : 0.0f;
      step[u] = valid & (step[u] > step_ratio * z[u]) ? 1.0f : 0.0f;
    }
  }
}

PANMAP_VECTOR_CLONES
void NormalEstimator::addRow(const DepthGeometry& g, int v, float sign, float* columns) const {
  const int width = g.width;
  const size_t padded = paddedWidth(width);
  const size_t row = g.index(0, v);
  const float* __restrict x = g.x_m.data() + row;
  const float* __restrict y = g.y_m.data() + row;
  const float* __restrict z = g.z_m.data() + row;
  const float* __restrict step = g.surface_step.data() + row;
  float* __restrict cx = columns + kX * padded + r_;
  float* __restrict cy = columns + kY * padded + r_;
  float* __restrict cz = columns + kZ * padded + r_;
  float* __restrict cu = columns + kUsable * padded + r_;
#pragma GCC ivdep
  for (int u = 0; u < width; ++u) {
    cx[u] += sign * x[u];
    cy[u] += sign * y[u];
    cz[u] += sign * z[u];
    cu[u] += (z[u] > 0.0f ? sign : 0.0f) - sign * kStepWeight * step[u];
  }
}

void NormalEstimator::sumColumns(const DepthGeometry& g, int v_begin, int v_end,
                                 float* columns) const {
  std::fill_n(columns, kChannels * paddedWidth(g.width), 0.0f);
  for (int v = v_begin; v <= v_end; ++v) addRow(g, v, 1.0f, columns);
}

// out[k] = sum of the padded columns [k, k + r], i.e. of image columns [k - r, k] clipped to
// the image, for k in [0, width + r): the left quadrant of pixel u is out[u], the right one
// out[u + r]. The r + 1 terms are summed from sums of 2^b consecutive columns (one pass per
// power of two, then one per set bit of r + 1): fewer passes than r adds, and direct sums
// rather than running ones, so nothing drifts along the row.
PANMAP_VECTOR_CLONES
void NormalEstimator::windowSums(const float* columns, int channels, int width, float* out) {
  const size_t padded = paddedWidth(width);
  const size_t windows = static_cast<size_t>(width) + r_;
  const int terms = r_ + 1;
  int levels = 0;
  while ((2 << levels) <= terms) ++levels;
  powers_.resize(static_cast<size_t>(levels) * padded);
  for (int c = 0; c < channels; ++c) {
    const float* in = columns + c * padded;
    // powers_[b - 1][k] = sum of in[k, k + 2^b).
    for (int b = 1; b <= levels; ++b) {
      const float* __restrict prev = b == 1 ? in : powers_.data() + (b - 2) * padded;
      float* __restrict next = powers_.data() + (b - 1) * padded;
      const size_t half = size_t{1} << (b - 1);
      const size_t count = padded - (size_t{1} << b) + 1;
#pragma GCC ivdep
      for (size_t k = 0; k < count; ++k) next[k] = prev[k] + prev[k + half];
    }
    float* __restrict sum = out + c * windows;
    size_t offset = 0;
    bool first = true;
    for (int b = levels; b >= 0; --b) {
      if (!(terms & (1 << b))) continue;
      const float* __restrict part =
          b == 0 ? in + offset : powers_.data() + (b - 1) * padded + offset;
      if (first) {
        std::copy_n(part, windows, sum);
        first = false;
      } else {
#pragma GCC ivdep
        for (size_t k = 0; k < windows; ++k) sum[k] += part[k];
      }
      offset += size_t{1} << b;
    }
  }
}

// The normal is the cross product of two spans of the window: from the mean point of its
// left side to that of its right side, and from its top to its bottom. The window is split
// into four quadrants (each including the centre row and column); a quadrant counts only when
// it holds no surface step (a depth discontinuity between valid pixels) and enough valid
// pixels: points of another surface would tilt the normal, and the tilt reads as a concave
// band beside every depth edge; holes only thin the average.
// A side is the mean of its usable quadrants' means; a side without one takes the halves of
// the centre column (or row) that lie in the opposite side's usable quadrants, so a single
// usable quadrant is enough: its mean and its halves of the centre row and column span it.
// On a plane every mean lies on the plane and the normal is exact; noise averages over the
// quadrants. All cases are one branch-free formula with 0/1 weights, so the loop vectorises.
PANMAP_VECTOR_CLONES
void NormalEstimator::normalsOfRow(int v, DepthGeometry* geometry) {
  DepthGeometry& g = *geometry;
  const int width = g.width;
  const int r = r_;
  const size_t windows = static_cast<size_t>(width) + r;
  const size_t padded = paddedWidth(width);
  const size_t row = g.index(0, v);
  const float* __restrict px = g.x_m.data() + row;
  const float* __restrict py = g.y_m.data() + row;
  const float* __restrict pz = g.z_m.data() + row;
  float* __restrict nx = g.nx.data() + row;
  float* __restrict ny = g.ny.data() + row;
  float* __restrict nz = g.nz.data() + row;
  float* __restrict has = g.has_normal.data() + row;
  const float* __restrict cols_l = cols_left_.data();
  const float* __restrict cols_r = cols_right_.data();
  const float* __restrict inv_cols_l = inv_cols_left_.data();
  const float* __restrict inv_cols_r = inv_cols_right_.data();
  const float rows_top = static_cast<float>(v - std::max(0, v - r) + 1);
  const float rows_bottom = static_cast<float>(std::min(g.height - 1, v + r) - v + 1);
  const float inv_rows_top = 1.0f / rows_top;
  const float inv_rows_bottom = 1.0f / rows_bottom;
  const float min_valid_top = kMinValidFraction * rows_top;
  const float min_valid_bottom = kMinValidFraction * rows_bottom;
  // Per channel: quadrant sums, centre column halves (rows [v - r, v] and [v, v + r]) and
  // centre row halves (columns [u - r, u] and [u, u + r]).
  const float* __restrict tl[kChannels];
  const float* __restrict tr[kChannels];
  const float* __restrict bl[kChannels];
  const float* __restrict br[kChannels];
  const float* __restrict col_t[kRowChannels];
  const float* __restrict col_b[kRowChannels];
  const float* __restrict row_l[kRowChannels];
  const float* __restrict row_r[kRowChannels];
  for (int c = 0; c < kChannels; ++c) {
    tl[c] = window_top_.data() + c * windows;
    tr[c] = tl[c] + r;
    bl[c] = window_bottom_.data() + c * windows;
    br[c] = bl[c] + r;
  }
  for (int c = 0; c < kRowChannels; ++c) {
    col_t[c] = top_.data() + c * padded + r;
    col_b[c] = bottom_.data() + c * padded + r;
    row_l[c] = row_window_.data() + c * windows;
    row_r[c] = row_l[c] + r;
  }
#pragma GCC ivdep
  for (int u = 0; u < width; ++u) {
    // A quadrant is usable with no step and enough valid pixels (see kUsable).
    const float use_tl = 1.0f - isNegative(tl[kUsable][u] - min_valid_top * cols_l[u]);
    const float use_tr = 1.0f - isNegative(tr[kUsable][u] - min_valid_top * cols_r[u]);
    const float use_bl = 1.0f - isNegative(bl[kUsable][u] - min_valid_bottom * cols_l[u]);
    const float use_br = 1.0f - isNegative(br[kUsable][u] - min_valid_bottom * cols_r[u]);
    const float no_left = (1.0f - use_tl) * (1.0f - use_bl);
    const float no_right = (1.0f - use_tr) * (1.0f - use_br);
    const float no_top = (1.0f - use_tl) * (1.0f - use_tr);
    const float no_bottom = (1.0f - use_bl) * (1.0f - use_br);
    // Halves of the centre column / row stand in for an empty side when they lie in a usable
    // quadrant and hold no hole (so their means are sums over known areas).
    const float full_ct = isZero(rows_top - col_t[kUsable][u]);
    const float full_cb = isZero(rows_bottom - col_b[kUsable][u]);
    const float full_rl = isZero(cols_l[u] - row_l[kUsable][u]);
    const float full_rr = isZero(cols_r[u] - row_r[kUsable][u]);
    const float right_ct = no_right * use_tl * full_ct, right_cb = no_right * use_bl * full_cb;
    const float left_ct = no_left * use_tr * full_ct, left_cb = no_left * use_br * full_cb;
    const float bottom_rl = no_bottom * use_tl * full_rl;
    const float bottom_rr = no_bottom * use_tr * full_rr;
    const float top_rl = no_top * use_bl * full_rl, top_rr = no_top * use_br * full_rr;
    // Each side averages 0, 1 or 2 means; 1.5 - 0.5 n is 1 / n for n = 1, 2 without a division
    // (an empty side has a zero sum and fails `ok` below).
    const float n_right = use_tr + use_br + right_ct + right_cb;
    const float n_left = use_tl + use_bl + left_ct + left_cb;
    const float n_bottom = use_bl + use_br + bottom_rl + bottom_rr;
    const float n_top = use_tl + use_tr + top_rl + top_rr;
    const float i_right = 1.5f - 0.5f * n_right, i_left = 1.5f - 0.5f * n_left;
    const float i_bottom = 1.5f - 0.5f * n_bottom, i_top = 1.5f - 0.5f * n_top;
    // Quadrant means over their valid pixels (the usable sum is the count); unusable quadrants
    // weigh 0.
    const float a_tl = use_tl / (tl[kUsable][u] + kTiny);
    const float a_tr = use_tr / (tr[kUsable][u] + kTiny);
    const float a_bl = use_bl / (bl[kUsable][u] + kTiny);
    const float a_br = use_br / (br[kUsable][u] + kTiny);
    float h[3], w[3];
    for (int c = 0; c < 3; ++c) {
      const float m_tl = a_tl * tl[c][u];
      const float m_tr = a_tr * tr[c][u];
      const float m_bl = a_bl * bl[c][u];
      const float m_br = a_br * br[c][u];
      const float m_ct = inv_rows_top * col_t[c][u];
      const float m_cb = inv_rows_bottom * col_b[c][u];
      const float m_rl = inv_cols_l[u] * row_l[c][u];
      const float m_rr = inv_cols_r[u] * row_r[c][u];
      const float right = (m_tr + m_br + right_ct * m_ct + right_cb * m_cb) * i_right;
      const float left = (m_tl + m_bl + left_ct * m_ct + left_cb * m_cb) * i_left;
      const float bottom = (m_bl + m_br + bottom_rl * m_rl + bottom_rr * m_rr) * i_bottom;
      const float top = (m_tl + m_tr + top_rl * m_rl + top_rr * m_rr) * i_top;
      h[c] = right - left;
      w[c] = bottom - top;
    }
    // w x h points toward the camera for a fronto-parallel plane (x right, y down).
    const float n0 = w[1] * h[2] - w[2] * h[1];
    const float n1 = w[2] * h[0] - w[0] * h[2];
    const float n2 = w[0] * h[1] - w[1] * h[0];
    const float length2 = n0 * n0 + n1 * n1 + n2 * n2;
    const float spans2 =
        (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]) * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    // A valid centre, every side non-empty (two diagonal quadrants alone give parallel
    // spans), and spans not parallel; as 0/1 factors.
    const float ok = isNegative(kMinDepthM - pz[u]) * isNegative(0.5f - n_right) *
                     isNegative(0.5f - n_left) * isNegative(0.5f - n_bottom) *
                     isNegative(0.5f - n_top) *
                     isNegative(kMinSpanSine * kMinSpanSine * spans2 - length2);
    // Toward the camera: the normal and the viewing ray to the point oppose.
    const float away = isNegative(-(n0 * px[u] + n1 * py[u] + n2 * pz[u]));
    const float scale = ok * (1.0f - 2.0f * away) * inverseSqrt(length2 + kTiny);
    nx[u] = n0 * scale;
    ny[u] = n1 * scale;
    nz[u] = n2 * scale;
    has[u] = ok;
  }
}

void NormalEstimator::computeRows(int window_px, int v0, int v1, DepthGeometry* geometry) {
  const DepthGeometry& g = *geometry;
  const int width = g.width;
  const int height = g.height;
  r_ = window_px / 2;
  const int r = r_;
  const size_t padded = paddedWidth(width);
  const size_t windows = static_cast<size_t>(width) + r;
  top_.resize(kChannels * padded);
  bottom_.resize(kChannels * padded);
  window_top_.resize(kChannels * windows);
  window_bottom_.resize(kChannels * windows);
  row_.assign(kRowChannels * padded, 0.0f);
  row_window_.resize(kRowChannels * windows);
  cols_left_.resize(width);
  cols_right_.resize(width);
  inv_cols_left_.resize(width);
  inv_cols_right_.resize(width);
  for (int u = 0; u < width; ++u) {
    cols_left_[u] = static_cast<float>(u - std::max(0, u - r) + 1);
    cols_right_[u] = static_cast<float>(std::min(width - 1, u + r) - u + 1);
    inv_cols_left_[u] = 1.0f / cols_left_[u];
    inv_cols_right_[u] = 1.0f / cols_right_[u];
  }

  // Running column sums, recomputed every kResyncRows image rows to bound the float drift.
  // A band starts at the last recomputed row before it, so every row's sums (and normals) are
  // the same whichever band, and thread, computes it.
  for (int v = v0 - v0 % kResyncRows; v < v1; ++v) {
    if (v % kResyncRows == 0) {
      sumColumns(g, std::max(0, v - r), v, top_.data());
      sumColumns(g, v, std::min(height - 1, v + r), bottom_.data());
    } else {
      addRow(g, v, 1.0f, top_.data());
      if (v - r - 1 >= 0) addRow(g, v - r - 1, -1.0f, top_.data());
      addRow(g, v - 1, -1.0f, bottom_.data());
      if (v + r < height) addRow(g, v + r, 1.0f, bottom_.data());
    }
    if (v < v0) continue;
    windowSums(top_.data(), kChannels, width, window_top_.data());
    windowSums(bottom_.data(), kChannels, width, window_bottom_.data());
    const size_t i0 = g.index(0, v);
    std::copy_n(g.x_m.data() + i0, width, row_.data() + r);
    std::copy_n(g.y_m.data() + i0, width, row_.data() + padded + r);
    std::copy_n(g.z_m.data() + i0, width, row_.data() + 2 * padded + r);
    float* valid = row_.data() + 3 * padded + r;
    for (int u = 0; u < width; ++u) valid[u] = g.z_m[i0 + u] > 0.0f ? 1.0f : 0.0f;
    windowSums(row_.data(), kRowChannels, width, row_window_.data());
    normalsOfRow(v, geometry);
  }
}

}  // namespace internal
}  // namespace panmap
