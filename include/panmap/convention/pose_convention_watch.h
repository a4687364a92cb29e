#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "panmap/convention/pose_convention.h"

namespace panmap {

/// Parameters of PoseConventionWatch.
struct PoseConventionWatchConfig {
  double window_every_s = 20.0;    ///< stream time between window starts
  int max_windows = 4;             ///< windows looked at, then the watch stops
  PoseConventionConfig agreement;  ///< how frame pairs are compared and a reading is chosen
  /// Throws Error naming the bad field.
  void check() const;
};

/// The pose-convention check over a stream of frames, for poses that arrive live (a SLAM
/// system's API may give world-to-camera: ORB-SLAM3's TrackRGBD returns T_cw; Eigen's
/// coeffs() gives a quaternion x y z w where pose_t wants w x y z). It keeps the frames of a
/// window that are 0, 0.1, 0.33 and 1 s after its first (a wrong quaternion order keeps
/// frames 0.1 s apart agreeing on 90 % of their points: it shows over the longer pairs), checks
/// them once the window is full, and says so when another reading agrees clearly better with
/// the depth. A camera that does not move in a window decides nothing; windows start every
/// window_every_s of stream time, up to max_windows. The poses are the sender's: nothing is
/// changed.
class PoseConventionWatch {
 public:
  using Config = PoseConventionWatchConfig;

  /// @param config parameters (checked)
  explicit PoseConventionWatch(const Config& config = Config());

  /// Offers the stream's next frame (by utime) with the pose it came with; keeps a copy of its
  /// depth when the window needs it and checks a full window.
  void add(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C_given);

  /// The check that found another reading clearly better, once one has.
  const std::optional<PoseConventionVerdict>& finding() const { return finding_; }

  /// One line for the status channel and the end of a run ("" when nothing was found).
  std::string warning() const;

 private:
  Config config_;
  std::vector<PoseSample> window_;
  int64_t next_window_utime_ = INT64_MIN;
  int windows_done_ = 0;
  std::optional<PoseConventionVerdict> finding_;
};

}  // namespace panmap
