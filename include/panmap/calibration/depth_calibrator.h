#pragma once

#include <functional>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/calibration/depth_calibration.h"
#include "panmap/core/frame.h"
#include "panmap/core/thread_pool.h"

namespace panmap {

/// One depth frame and the pose it was seen from: what DepthCalibrator learns from.
struct CalibrationFrame {
  PinholeCamera camera;
  double depth_scale_m = 0.001;
  DepthImage depth;  ///< as the sensor read it
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
};

/// What one pass of DepthCalibrator::calibrate() saw.
struct CalibrationPass {
  double rms_residual_m = 0.0;  ///< RMS depth disagreement of the points with the map
  int64_t points = 0;           ///< points on the map's surface that counted
};

/// Learns a DepthCalibration from frames with poses, by alternation: map the frames (corrected
/// by the calibration so far) into a TSDF, measure each point's depth disagreement with that
/// map along its ray (the signed distance at the point over the cosine between ray and surface
/// normal), and add its mean per grid cell and depth knot (shrunk towards 0 where few points
/// count) to the calibration; repeat. A map built from many viewpoints averages the sensor's
/// pattern away, so a frame's disagreement with it is the pattern; but the map still holds part
/// of each frame's error, so one pass measures only part of it, and the passes add up to the
/// whole. What the data cannot tell from a scale error is left out: the mean offset of each
/// depth knot is removed, so the calibration bends depth, never scales it.
///
/// The poses should be good: a wrong pose also disagrees with the map, in a pattern that moves
/// from frame to frame and mostly averages out, but not wholly. Poses refined by the mapper's
/// own tracking improve with a calibration, so calibrating again from them converges
/// (panmap-calibrate-depth --rounds). Deterministic, whatever the thread count.
class DepthCalibrator {
 public:
  /// Parameters; units in the names.
  struct Config {
    int cells_x = 32;             ///< image cells across (20 px on a 640 px image)
    int cells_y = 24;             ///< image cells down
    int knots = 9;                ///< depth knots at 0, spacing, 2 spacing, ...
    double knot_spacing_m = 0.5;  ///< (9 knots of 0.5 m reach 4 m)
    float voxel_size_m = 0.01f;   ///< of the TSDF the frames are compared with
    double max_depth_m = 3.5;     ///< depth beyond this is neither mapped nor measured
    int pixel_stride = 2;         ///< pixels between measured points, each way
    /// Points farther than this from the map's surface are not on it: left out.
    double max_residual_m = 0.03;
    /// Points seen at a grazing angle (|cos(ray, normal)| below this) are left out.
    double min_cos = 0.5;
    /// Grid values with less point weight than this keep their offset (too few points).
    double min_weight = 50.0;
    /// Shrinkage: each pass moves a grid value by its points' summed disagreement over (their
    /// weight + this), so a value that few noisy points reach stays near 0.
    double prior_weight = 1000.0;
    int passes = 6;  ///< map-and-measure alternations
    /// Throws Error naming the bad field.
    void check() const;
  };

  /// Throws Error when the config is invalid.
  explicit DepthCalibrator(const Config& config);

  /// Learns from `frames` (at least one; all of one image size). Offsets are rounded as a
  /// calibration file keeps them (quantiseOffsetM). Throws Error on frames of mixed sizes, an
  /// invalid camera, or when no point lands on the map.
  /// @param pool threads for mapping the frames (not owned)
  /// @param passes if not null, receives what each pass saw
  /// @param progress if set, called after each pass with (passes done, passes in all)
  DepthCalibration calibrate(const std::vector<CalibrationFrame>& frames, ThreadPool* pool,
                             std::vector<CalibrationPass>* passes = nullptr,
                             const std::function<void(int, int)>& progress = {}) const;

  /// The config in use.
  const Config& config() const { return config_; }

 private:
  Config config_;
};

}  // namespace panmap
