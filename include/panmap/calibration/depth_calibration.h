#pragma once

#include <string>
#include <vector>

#include "panmap/calibration/internal/grid_lerp.h"
#include "panmap/core/frame.h"
#include "panmap/core/image.h"
#include "panmap/core/thread_pool.h"

namespace panmap {

/// A depth sensor's fixed-pattern depth error, removed from every frame before it is mapped.
///
/// Structured-light and stereo depth sensors read depth with an error that depends on the pixel
/// and the depth: the Kinect v1 bends planes by up to a centimetre at 2-3 m (Herrera, Kannala
/// and Heikkila, "Joint depth and color camera calibration with distortion correction", PAMI
/// 2012; Teichman, Miller and Thrun, "Unsupervised intrinsic calibration of depth sensors via
/// SLAM", RSS 2013). The pattern moves with the camera, so a frame never agrees with a map that
/// averages it over many viewpoints; frame-to-model pose refinement then absorbs the
/// disagreement into the pose, and the error ratchets into drift (docs/MAPPING.md).
///
/// The model is an offset in metres added to the depth read at a pixel: bilinear between the
/// centres of a grid of image cells, linear between depth knots at 0, s, 2 s, ... (held beyond
/// the last knot). It belongs to one sensor at one image size; DepthCalibrator learns it.
/// An empty calibration changes nothing.
class DepthCalibration {
 public:
  /// The identity: no correction.
  DepthCalibration() = default;

  /// A calibration of `width` x `height` images over cells_x x cells_y cells and `knots` depth
  /// knots `knot_spacing_m` apart. offsets_m holds knots x cells_y x cells_x values (x fastest,
  /// then y, then the knot). Throws Error on a bad size, spacing or a non-finite offset.
  DepthCalibration(int width, int height, int cells_x, int cells_y, int knots,
                   double knot_spacing_m, std::vector<float> offsets_m);

  /// True for the identity.
  bool empty() const { return offsets_m_.empty(); }
  int width() const { return width_; }    ///< image width it applies to, pixels
  int height() const { return height_; }  ///< image height it applies to, pixels
  int cellsX() const { return cells_x_; }
  int cellsY() const { return cells_y_; }
  int knots() const { return knots_; }
  double knotSpacingM() const { return knot_spacing_m_; }
  /// The grid values, metres (knots x cells_y x cells_x, x fastest).
  const std::vector<float>& offsetsM() const { return offsets_m_; }

  /// Offset (metres) to add to a depth of z_m read at pixel (u, v); 0 for the identity.
  double offsetM(double u, double v, double z_m) const;

  /// The reading `raw` (units of depth_scale_m; 0 = none, kept) at pixel (u, v) corrected, as
  /// apply() corrects it, bit for bit: for the few pixels of a frame that are needed.
  uint16_t correctedReading(int u, int v, uint16_t raw, double depth_scale_m) const;

  /// `raw` (depth units of depth_scale_m, 0 = no reading) with the offsets added, rounded to
  /// the unit; readings stay readings (at least 1 unit). Throws Error when the image size differs
  /// from the calibration's; the identity copies.
  /// @param pool if not null, rows are shared among its threads (the same result)
  void apply(const DepthImage& raw, double depth_scale_m, DepthImage* corrected,
             ThreadPool* pool = nullptr) const;

  /// `raw` with its depth corrected (apply() above), everything else copied; `corrected`'s
  /// buffers are reused. Throws Error, leaving `corrected` as it was, on a size mismatch.
  void apply(const RgbdFrame& raw, RgbdFrame* corrected, ThreadPool* pool = nullptr) const;

  /// RMS of the grid values, metres.
  double rmsOffsetM() const;

  /// Writes a JSON file (format "panmap-depth-calibration", version 1) atomically. Throws Error
  /// naming the file on failure.
  void save(const std::string& path) const;
  /// Reads a file written by save(). Throws Error naming the file and what is wrong with it.
  static DepthCalibration load(const std::string& path);

  bool operator==(const DepthCalibration& other) const;
  bool operator!=(const DepthCalibration& other) const { return !(*this == other); }

 private:
  // The offset at interpolated image coordinates and a depth.
  double offsetAt(const internal::GridLerp& x, const internal::GridLerp& y, double z_m) const;
  // A non-zero reading corrected and rounded to the unit, at least 1.
  uint16_t roundedUnits(uint16_t raw, double depth_scale_m, double units_per_m,
                        const internal::GridLerp& x, const internal::GridLerp& y) const;

  int width_ = 0, height_ = 0;
  int cells_x_ = 0, cells_y_ = 0, knots_ = 0;
  double knot_spacing_m_ = 0.0;
  std::vector<float> offsets_m_;
};

/// An offset rounded to the tenth of a millimetre a calibration file keeps, so that a calibration
/// of rounded offsets saves and loads as the same floats.
float quantiseOffsetM(double offset_m);

}  // namespace panmap
