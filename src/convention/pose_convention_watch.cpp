#include "panmap/convention/pose_convention_watch.h"

#include <cmath>

#include "panmap/core/error.h"

namespace panmap {

namespace {

// The window's frames, by their time after its first one, microseconds: 3, 10 and 30 frames
// at 30 Hz, as panmap-import pairs a file's frames.
constexpr int64_t kOffsetsUs[] = {0, 100000, 333000, 1000000};
// Pairs of the window's frames compared.
const std::vector<std::pair<int, int>> kPairs = {{0, 1}, {0, 2}, {1, 2}, {2, 3}, {0, 3}};

}  // namespace

void PoseConventionWatchConfig::check() const {
  if (!(window_every_s > 1.0) || !std::isfinite(window_every_s)) {
    throw Error("pose convention watch window_every_s must exceed a window's 1 s");
  }
  if (max_windows < 0) throw Error("pose convention watch max_windows must be >= 0");
  agreement.check();
}

PoseConventionWatch::PoseConventionWatch(const Config& config) : config_(config) {
  config_.check();
}

void PoseConventionWatch::add(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C_given) {
  if (finding_ || windows_done_ >= config_.max_windows) return;
  if (window_.empty()) {
    if (frame.utime < next_window_utime_) return;
  } else if (frame.utime - window_.front().frame.utime < kOffsetsUs[window_.size()]) {
    return;
  }
  PoseSample sample;
  sample.frame.utime = frame.utime;
  sample.frame.camera = frame.camera;
  sample.frame.depth_scale_m = frame.depth_scale_m;
  sample.frame.depth = frame.depth;  // colour is not looked at
  sample.T_as_read = T_W_C_given;
  window_.push_back(std::move(sample));
  if (window_.size() < std::size(kOffsetsUs)) return;
  PoseConventionVerdict verdict = detectPoseConvention(
      window_, kPairs, QuaternionInput::kScalarFirst, PoseConventionChoice(), config_.agreement);
  if (verdict.changed) finding_ = std::move(verdict);
  next_window_utime_ =
      window_.front().frame.utime + static_cast<int64_t>(config_.window_every_s * 1e6);
  window_.clear();
  ++windows_done_;
}

std::string PoseConventionWatch::warning() const {
  if (!finding_) return "";
  return "poses: the depth of " + std::to_string(finding_->pairs) + " frame pairs agrees on " +
         std::to_string(static_cast<int>(100.0 * finding_->agreement_as_read + 0.5)) +
         " % of points at the poses as sent, and on " +
         std::to_string(static_cast<int>(100.0 * finding_->agreement_chosen + 0.5)) +
         " % read as " + finding_->convention.describe() +
         ": check the sender's convention (CAMERA_POSE carries T_W_C of the optical frame, camera "
         "to world, metres, quaternion w x y z)";
}

}  // namespace panmap
