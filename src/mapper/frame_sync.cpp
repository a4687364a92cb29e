#include "panmap/mapper/frame_sync.h"

#include <algorithm>
#include <cstdlib>
#include <iterator>

#include "panmap/core/error.h"

namespace panmap {

void SyncConfig::check() const {
  if (pose_tolerance_us < 0) throw Error("sync pose_tolerance_us must be >= 0");
  if (max_pose_gap_us < 0) throw Error("sync max_pose_gap_us must be >= 0");
  if (mask_tolerance_us < 0) throw Error("sync mask_tolerance_us must be >= 0");
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
  // Beyond max_queue, popReady() sends the oldest on (or drops it): it is called after every
  // message, so the queue never holds more than one frame over.
  frames_.insert(at, std::move(frame));
}

void FrameSynchronizer::addPose(const StampedPose& pose) {
  if (!poses_.emplace(pose.utime, pose).second) ++stats_.repeated_poses;
}

void FrameSynchronizer::skipFrame(int64_t utime) {
  skipped_.insert(utime);
  // At most the masks a network sends while frames wait: older skips can have no mask to come.
  constexpr size_t kMaxSkipped = 4096;
  while (skipped_.size() > kMaxSkipped) skipped_.erase(skipped_.begin());
  const int64_t tolerance = config_.mask_tolerance_us;
  for (auto it = panoptics_.lower_bound(utime - tolerance);
       it != panoptics_.end() && it->first <= utime + tolerance;) {
    if (ofSkippedFrame(it->first)) {
      ++stats_.panoptic_of_skipped_frames;
      it = panoptics_.erase(it);
    } else {
      ++it;
    }
  }
}

bool FrameSynchronizer::ofSkippedFrame(int64_t utime) const {
  const int64_t tolerance = config_.mask_tolerance_us;
  const auto it = skipped_.lower_bound(utime - tolerance);
  if (it == skipped_.end() || *it > utime + tolerance) return false;
  // The nearest skipped frame, unless a waiting frame is nearer: that one keeps the mask.
  int64_t skipped_gap = std::abs(*it - utime);
  const auto next = std::next(it);
  if (next != skipped_.end() && *next <= utime + tolerance) {
    skipped_gap = std::min(skipped_gap, std::abs(*next - utime));
  }
  for (const RgbdFrame& f : frames_) {
    if (std::abs(f.utime - utime) < skipped_gap) return false;
  }
  return true;
}

void FrameSynchronizer::addPanoptic(PanopticFrame panoptic) {
  const int64_t utime = panoptic.utime;
  newest_mask_ = std::max(newest_mask_, utime);
  if (ofSkippedFrame(utime)) {
    ++stats_.panoptic_of_skipped_frames;
    return;
  }
  // Frames go in utime order: a handled frame at or after utime - tolerance is this mask's
  // frame (or one past it), mapped or refused already.
  if (newest_handled_ >= utime - config_.mask_tolerance_us) {
    ++stats_.late_panoptic;
    return;
  }
  if (!panoptics_.emplace(utime, std::move(panoptic)).second) ++stats_.repeated_panoptic;
}

std::map<int64_t, PanopticFrame>::iterator FrameSynchronizer::maskFor(int64_t utime) {
  const int64_t tolerance = config_.mask_tolerance_us;
  auto best = panoptics_.end();
  for (auto it = panoptics_.lower_bound(utime - tolerance);
       it != panoptics_.end() && it->first <= utime + tolerance; ++it) {
    if (best == panoptics_.end() || std::abs(it->first - utime) < std::abs(best->first - utime)) {
      best = it;
    }
  }
  return best;
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
    // A full queue sends the oldest frame on with what it has.
    const bool pressed = frames_.size() > config_.max_queue;
    bool interpolated = false;
    PoseSource source = PoseSource::kUnknown;
    const auto pose = poseAt(frame.utime, timed_out || pressed, &interpolated, &source);
    const auto mask = maskFor(frame.utime);
    if (!pose) {
      if (!timed_out && !pressed) break;  // keep order: later frames wait behind this one
      ++(timed_out ? stats_.rejected_no_pose : stats_.dropped_queue_full);
      if (timed_out) countPoseGap(frame.utime);
      newest_handled_ = std::max(newest_handled_, frame.utime);
      frames_.pop_front();
      continue;
    }
    // With masks in order, a mask of a later frame says this frame's will not come.
    const bool mask_skipped =
        config_.masks_in_order && newest_mask_ > frame.utime + config_.mask_tolerance_us;
    if (mask == panoptics_.end() && !timed_out && !mask_skipped && !pressed) break;
    SyncedFrame out;
    out.T_W_C = *pose;
    out.pose_source = source;
    out.pose_interpolated = interpolated;
    if (mask != panoptics_.end()) {
      if (mask->first != frame.utime) ++stats_.panoptic_time_offset;
      out.panoptic = std::move(mask->second);
      out.panoptic->utime = frame.utime;  // the frame's, as everything after matching expects
      panoptics_.erase(mask);
    } else {
      ++stats_.geometry_only;
      if (!timed_out && !mask_skipped) ++stats_.geometry_only_queue_full;
    }
    newest_handled_ = std::max(newest_handled_, frame.utime);
    out.frame = std::move(frame);
    frames_.pop_front();
    ++stats_.frames_out;
    ready.push_back(std::move(out));
  }
  // Masks no frame can take any more: their frame was handled (frames go in utime order), or
  // would have waited too long by now. A frame that arrives late but before those keeps its
  // mask (it used to be dropped as older than the oldest waiting frame).
  const int64_t tolerance = config_.mask_tolerance_us;
  const int64_t expired = now_utime - config_.wait_us;
  for (auto it = panoptics_.begin();
       it != panoptics_.end() &&
       (newest_handled_ >= it->first - tolerance || it->first + tolerance < expired);) {
    if (ofSkippedFrame(it->first)) {
      ++stats_.panoptic_of_skipped_frames;
    } else {
      ++stats_.unmatched_panoptic;
      stats_.last_unmatched_gap_us = nearestFrameGap(it->first);
    }
    it = panoptics_.erase(it);
  }
  const int64_t oldest = frames_.empty() ? expired : frames_.front().utime;
  prunePoses(oldest - config_.max_pose_gap_us);
  return ready;
}

std::vector<SyncedFrame> FrameSynchronizer::flush() {
  std::vector<SyncedFrame> ready = popReady(INT64_MAX / 2);
  stats_.unmatched_panoptic += static_cast<int64_t>(panoptics_.size());
  panoptics_.clear();
  return ready;
}

void FrameSynchronizer::countPoseGap(int64_t utime) {
  const auto after = poses_.lower_bound(utime);
  if (after == poses_.end() || after == poses_.begin()) return;
  ++stats_.rejected_pose_gap;
  stats_.last_pose_gap_us = after->first - std::prev(after)->first;
}

int64_t FrameSynchronizer::nearestFrameGap(int64_t utime) const {
  int64_t gap = newest_handled_ == INT64_MIN ? -1 : std::abs(utime - newest_handled_);
  for (const RgbdFrame& f : frames_) {
    const int64_t d = std::abs(utime - f.utime);
    if (gap < 0 || d < gap) gap = d;
  }
  return gap;
}

void FrameSynchronizer::prunePoses(int64_t oldest_needed) {
  // Keep one pose before the oldest needed time for interpolation.
  auto it = poses_.lower_bound(oldest_needed);
  if (it != poses_.begin()) --it;
  poses_.erase(poses_.begin(), it);
}

}  // namespace panmap
