#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace panmap {

/// One colour pixel, 8 bits per channel, in R G B order.
struct Rgb8 {
  uint8_t r = 0;
  uint8_t g = 0;
  uint8_t b = 0;
  bool operator==(const Rgb8& o) const { return r == o.r && g == o.g && b == o.b; }
  bool operator!=(const Rgb8& o) const { return !(*this == o); }
};

/// A row-major image that owns its pixels: a plain buffer, so the core stays free of OpenCV.
template <typename T>
class Image {
 public:
  using Pixel = T;

  Image() = default;
  /// Allocates width x height pixels set to `fill`.
  Image(int width, int height, const T& fill = T())
      : width_(width), height_(height), pixels_(static_cast<size_t>(width) * height, fill) {}

  /// Pixels per row.
  int width() const { return width_; }
  /// Rows.
  int height() const { return height_; }
  /// True when the image holds no pixel.
  bool empty() const { return pixels_.empty(); }
  /// Number of pixels.
  size_t size() const { return pixels_.size(); }
  /// Pixel at column u, row v (no bounds check in release builds).
  T& operator()(int u, int v) { return pixels_[static_cast<size_t>(v) * width_ + u]; }
  /// Pixel at column u, row v (no bounds check in release builds).
  const T& operator()(int u, int v) const { return pixels_[static_cast<size_t>(v) * width_ + u]; }
  /// First pixel of row v.
  T* row(int v) { return pixels_.data() + static_cast<size_t>(v) * width_; }
  /// First pixel of row v.
  const T* row(int v) const { return pixels_.data() + static_cast<size_t>(v) * width_; }
  /// All pixels, row-major.
  T* data() { return pixels_.data(); }
  /// All pixels, row-major.
  const T* data() const { return pixels_.data(); }
  /// Pixel storage, row-major.
  const std::vector<T>& pixels() const { return pixels_; }
  /// True when sizes and every pixel match.
  bool operator==(const Image& o) const {
    return width_ == o.width_ && height_ == o.height_ && pixels_ == o.pixels_;
  }

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<T> pixels_;
};

/// Depth in units of the frame's depth scale; 0 = no measurement.
using DepthImage = Image<uint16_t>;
/// Colour image.
using ColorImage = Image<Rgb8>;
/// Integer labels (panoptic segment ids, instance ids); 0 = none.
using LabelImage = Image<int32_t>;

}  // namespace panmap
