#include "panmap/mapper/frame_sync.h"

#include <algorithm>

#include "panmap/core/error.h"

namespace panmap {

void SyncConfig::check() const {
  if (pose_tolerance_us < 0) throw Error("sync pose_tolerance_us must be >= 0");
  if (max_pose_gap_us < 0) throw Error("sync max_pose_gap_us must be >= 0");
  if (wait_us < 0) throw Error("sync wait_us must be >= 0");
  if (max_queue < 1) throw Error("sync max_queue must be >= 1");
}

FrameSynchronizer::FrameSynchronizer(const SyncConfig& config) : config_(config) {
  config_.check();
}

void FrameSynchronizer::addFrame(RgbdFrame frame) {
  ++stats_.frames_in;
  if (frame.utime < newest_handled_) {
    ++stats_.out_of_order_frames;
    return;
  }
  const auto at =
      std::upper_bound(frames_.begin(), frames_.end(), frame.utime,
                       [](int64_t utime, const RgbdFrame& queued) { return utime < queued.utime; });
  if (frame.utime == newest_handled_ ||
      (at != frames_.begin() && std::prev(at)->utime == frame.utime)) {
    ++stats_.repeated_frames;
    return;
  }
  frames_.insert(at, std::move(frame));
  if (frames_.size() > config_.max_queue) {
    newest_handled_ = std::max(newest_handled_, frames_.front().utime);
    frames_.pop_front();
    ++stats_.dropped_queue_full;
  }
}

void FrameSynchronizer::addPose(const StampedPose& pose) {
  if (!poses_.emplace(pose.utime, pose).second) ++stats_.repeated_poses;
}

void FrameSynchronizer::addPanoptic(PanopticFrame panoptic) {
  const int64_t utime = panoptic.utime;
  if (utime <= newest_handled_) {
    ++stats_.late_panoptic;  // its frame is mapped (or refused) already
    return;
  }
  if (!panoptics_.emplace(utime, std::move(panoptic)).second) ++stats_.repeated_panoptic;
}

std::optional<Eigen::Isometry3d> FrameSynchronizer::poseAt(int64_t utime, bool final,
                                                           bool* interpolated,
                                                           PoseSource* source) const {
  *interpolated = false;
  const auto exact = poses_.find(utime);
  if (exact != poses_.end()) {
    *source = exact->second.source;
    return exact->second.T_W_C;
  }
  const auto after = poses_.lower_bound(utime);
  const bool has_after = after != poses_.end();
  const bool has_before = after != poses_.begin();
  if (has_before && has_after) {
    const auto before = std::prev(after);
    if (after->first - before->first <= config_.max_pose_gap_us) {
      const double t = static_cast<double>(utime - before->first) /
                       static_cast<double>(after->first - before->first);
      *interpolated = true;
      *source = before->second.source;
      return interpolatePose(before->second.T_W_C, after->second.T_W_C, t);
    }
  }
  // Nearest within the tolerance; a later pose may still come unless the stream has ended.
  const StampedPose* nearest = nullptr;
  int64_t best = config_.pose_tolerance_us + 1;
  if (has_after && after->first - utime < best)
    best = after->first - utime, nearest = &after->second;
  if (has_before) {
    const auto before = std::prev(after);
    if (utime - before->first < best) best = utime - before->first, nearest = &before->second;
  }
  if (nearest && (has_after || final)) {
    *source = nearest->source;
    return nearest->T_W_C;
  }
  return std::nullopt;
}

std::vector<SyncedFrame> FrameSynchronizer::popReady(int64_t now_utime) {
  std::vector<SyncedFrame> ready;
  while (!frames_.empty()) {
    RgbdFrame& frame = frames_.front();
    const bool timed_out = now_utime - frame.utime > config_.wait_us;
    bool interpolated = false;
    PoseSource source = PoseSource::kUnknown;
    const auto pose = poseAt(frame.utime, timed_out, &interpolated, &source);
    const auto mask = panoptics_.find(frame.utime);
    if (!pose) {
      if (!timed_out) break;  // keep order: later frames wait behind this one
      ++stats_.rejected_no_pose;
      newest_handled_ = std::max(newest_handled_, frame.utime);
      frames_.pop_front();
      continue;
    }
    if (mask == panoptics_.end() && !timed_out) break;
    SyncedFrame out;
    out.T_W_C = *pose;
    out.pose_source = source;
    out.pose_interpolated = interpolated;
    if (mask != panoptics_.end()) {
      out.panoptic = std::move(mask->second);
      panoptics_.erase(mask);
    } else {
      ++stats_.geometry_only;
    }
    newest_handled_ = std::max(newest_handled_, frame.utime);
    out.frame = std::move(frame);
    frames_.pop_front();
    ++stats_.frames_out;
    ready.push_back(std::move(out));
  }
  // Masks older than every waiting frame can no longer match.
  const int64_t oldest = frames_.empty() ? now_utime - config_.wait_us : frames_.front().utime;
  for (auto it = panoptics_.begin(); it != panoptics_.end() && it->first < oldest;) {
    ++stats_.unmatched_panoptic;
    it = panoptics_.erase(it);
  }
  prunePoses(oldest - config_.max_pose_gap_us);
  return ready;
}

std::vector<SyncedFrame> FrameSynchronizer::flush() {
  std::vector<SyncedFrame> ready = popReady(INT64_MAX / 2);
  stats_.unmatched_panoptic += static_cast<int64_t>(panoptics_.size());
  panoptics_.clear();
  return ready;
}

void FrameSynchronizer::prunePoses(int64_t oldest_needed) {
  // Keep one pose before the oldest needed time for interpolation.
  auto it = poses_.lower_bound(oldest_needed);
  if (it != poses_.begin()) --it;
  poses_.erase(poses_.begin(), it);
}

}  // namespace panmap
