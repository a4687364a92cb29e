#include "panmap/lcm/mapping_session.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <optional>
#include <utility>

#include <Eigen/Geometry>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/correction_conversions.h"
#include "panmap/lcm/decode.h"

namespace panmap {

StageTiming summariseTimes(std::vector<double> times_ms) {
  StageTiming t;
  if (times_ms.empty()) return t;
  t.last_ms = times_ms.back();
  const ValueSpread s = spreadOf(std::move(times_ms));
  t.median_ms = s.median;
  t.p95_ms = s.p95;
  return t;
}

std::string reasonOf(const std::string& what) {
  const auto colon = what.find(':');
  if (colon == std::string::npos) return what;
  // "rgbd frame 12: principal point ... lies outside ...": the head names one message, and
  // counted by it every frame was a reason of its own and what was wrong was lost. Heads nest
  // ("pose correction 7: pose 1100000: non-finite value").
  if (colon > 0 && std::isdigit(static_cast<unsigned char>(what[colon - 1]))) {
    const size_t rest = what.find_first_not_of(' ', colon + 1);
    if (rest != std::string::npos) {
      const std::string reason = what.substr(rest);
      const auto next = reason.find(':');
      const bool nested = next != std::string::npos && next > 0 &&
                          std::isdigit(static_cast<unsigned char>(reason[next - 1]));
      return nested ? reasonOf(reason) : reason;
    }
  }
  return what.substr(0, colon);
}

std::string storeFailure(const std::string& what) {
  // "cannot write DIR/frames/300000.depth.zst.partial: No space left on device": the file
  // names one frame, and counted by it every failed frame was a reason of its own.
  const auto colon = what.rfind(": ");
  const std::string cause = colon == std::string::npos ? what : what.substr(colon + 2);
  return "frame store: write failed (" + cause + "); the frame is mapped, a repair cannot move it";
}

MappingSession::MappingSession(const SessionOptions& options, Mapper* mapper)
    : options_(options), mapper_(mapper), sync_(options.sync) {
  if (!mapper_) throw Error("MappingSession: no mapper");
  if (!options_.grid_shift_m.allFinite()) throw Error("grid shift: not a finite translation");
  if (!options_.grid_shift_m.isZero(0.0) && options_.frame_store) {
    // Corrections come in the SLAM's frame, the stored poses would be in the moved one.
    throw Error("grid shift: a diagnostic of offline maps, not combined with a frame store");
  }
  if (options_.frame_store) {
    writer_ = std::make_unique<FrameStoreWriter>(options_.frame_store);
    // A loaded or resumed map with its store: corrections up to the last one in the map are
    // stale, as they were for the session that applied it.
    applied_before_ = options_.frame_store->lastCorrectionId();
  }
}

void MappingSession::countStoreErrors() {
  if (!writer_) return;
  // The map holds the frame either way; a frame the store lacks makes a later repair fail by
  // name, so the failure is counted as soon as it is known.
  for (const std::string& e : writer_->takeErrors()) ++stats_.rejected[storeFailure(e)];
}

void MappingSession::countDropped(const std::string& reason, int64_t n) {
  stats_.rejected[reason] += n;
}

void MappingSession::sanitise(PanopticFrame* panoptic) {
  // A category outside the label space would become a class of its own in votes and graph;
  // such segments are kept as unlabelled (category 0) pixels and counted.
  for (PanopticSegment& segment : panoptic->segments) {
    if (segment.category < 0 || segment.category > kMaxNyu40Class) {
      ++stats_.rejected["panoptic segment: unknown category"];
      segment.category = 0;
    }
  }
  // Pixels whose id no segment lists vote for nothing: a converter that numbers the pixels
  // and the segment list differently gave a map without classes and no word of why.
  std::vector<int32_t> listed;
  listed.reserve(panoptic->segments.size());
  for (const PanopticSegment& segment : panoptic->segments) listed.push_back(segment.id);
  std::sort(listed.begin(), listed.end());
  const LabelImage& ids = panoptic->segment_ids;
  const int32_t* id = ids.data();
  const size_t n = static_cast<size_t>(ids.width()) * static_cast<size_t>(ids.height());
  int32_t last_checked = 0;  // masks are piecewise constant: one lookup per run of an id
  for (size_t i = 0; i < n; ++i) {
    if (id[i] == 0 || id[i] == last_checked) continue;
    if (!std::binary_search(listed.begin(), listed.end(), id[i])) {
      ++stats_.rejected["panoptic: pixel ids that no segment lists (read as no segment)"];
      return;
    }
    last_checked = id[i];
  }
}

bool MappingSession::handle(const std::string& channel, const void* data, size_t size,
                            int64_t now_utime) {
  if (channel != options_.channel_rgbd && channel != options_.channel_pose &&
      channel != options_.channel_panoptic && channel != options_.channel_correction) {
    return false;
  }
  ++stats_.messages;
  if (done_) return true;
  try {
    if (channel == options_.channel_correction) {
      pose_correction_t msg;
      if (!decodeExactly(data, size, &msg)) {
        ++stats_.rejected["malformed " + channel];
        return true;
      }
      const PoseCorrection correction = fromMessage(msg);
      ++stats_.corrections_received;
      // Frames that are ready by now go in first: the repair moves every frame the map holds.
      // The correction's own utime is when the back-end published it, perhaps by another
      // clock (its wall clock against the sensor's): it does not move the stream's time, or
      // every frame after it was refused as waiting too long.
      integrate(sync_.popReady(now_utime >= 0 ? now_utime : newest_utime_));
      repair(correction);
      return true;
    } else if (channel == options_.channel_rgbd) {
      rgbd_frame_t msg;
      if (!decodeExactly(data, size, &msg)) {
        ++stats_.rejected["malformed " + channel];
        return true;
      }
      RgbdFrame frame = fromMessage(msg);
      ++stats_.frames_received;
      if (frame.utime <= options_.resume_after_utime) {
        stats_.resume_point_seen =
            stats_.resume_point_seen || frame.utime == options_.resume_after_utime;
        ++stats_.rejected["frame: mapped before the resume point"];
        sync_.skipFrame(frame.utime);  // its mask is no timing fault
        return true;
      }
      newest_utime_ = std::max(newest_utime_, frame.utime);
      sync_.addFrame(std::move(frame));
    } else if (channel == options_.channel_pose) {
      pose_t msg;
      if (!decodeExactly(data, size, &msg)) {
        ++stats_.rejected["malformed " + channel];
        return true;
      }
      const StampedPose pose = fromMessage(msg);
      newest_utime_ = std::max(newest_utime_, pose.utime);
      sync_.addPose(pose);
    } else {
      panoptic_t msg;
      if (!decodeExactly(data, size, &msg)) {
        ++stats_.rejected["malformed " + channel];
        return true;
      }
      PanopticFrame panoptic = fromMessage(msg);
      sanitise(&panoptic);
      newest_utime_ = std::max(newest_utime_, panoptic.utime);
      sync_.addPanoptic(std::move(panoptic));
    }
  } catch (const Error& error) {
    std::string reason = reasonOf(error.what());
    // A correction's checks end with the utimes they tripped on ("pose utimes must increase
    // (1200000 after 1300000)"): counted by what went wrong, one key however many arrive.
    if (channel == options_.channel_correction) reason = reason.substr(0, reason.find(" ("));
    ++stats_.rejected["bad " + channel + ": " + reason];
    return true;
  }
  integrate(sync_.popReady(now_utime >= 0 ? now_utime : newest_utime_));
  poll();
  return true;
}

void MappingSession::repair(const PoseCorrection& correction) {
  if (!options_.frame_store) {
    ++stats_.rejected["correction: no frame store (panmap-mapper --frame-store)"];
    return;
  }
  const bool running = background_ && background_->running();
  if ((stats_.corrections_applied > 0 && correction.correction_id <= stats_.last_correction_id) ||
      (applied_before_ && correction.correction_id <= *applied_before_) ||
      (running && correction.correction_id <= running_correction_id_)) {
    ++stats_.rejected["correction: not newer than the last one applied"];
    return;
  }
  if (options_.background_repair) {
    if (!background_) {
      FrameStoreWriter* writer = writer_.get();
      background_ = std::make_unique<BackgroundRepair>(
          mapper_,
          [writer](int64_t utime, RgbdFrame* frame, LabelImage* labels) {
            StoredFrame stored = writer->load(utime);  // waits for a frame still queued
            *frame = std::move(stored.rgbd);
            *labels = std::move(stored.labels);
          },
          options_.frame_store, options_.repair,
          [writer](int64_t utime, RgbdFrame* frame, PanopticFrame* panoptic,
                   GeometricSegments* kept) {
            StoredFrame stored = writer->load(utime);
            *frame = std::move(stored.rgbd);
            *panoptic = std::move(stored.panoptic);
            *kept = std::move(stored.geometric);
            return stored.has_panoptic;
          },
          // The writer may not have written any frame yet: what was handed to it counts.
          [this] { return stored_segmentation_ || options_.frame_store->sizeWithPanoptic() > 0; });
    }
    try {
      const MapRepairResult started = background_->start(correction);
      if (started.nothing_moved) {
        if (!started.unknown_utimes.empty()) {
          stats_.rejected["correction: utime of no mapped frame"] +=
              static_cast<int64_t>(started.unknown_utimes.size());
        }
        recordRepair(started);
        return;
      }
      if (running) ++stats_.corrections_superseded;
      running_correction_id_ = correction.correction_id;
      if (!started.unknown_utimes.empty()) {
        stats_.rejected["correction: utime of no mapped frame"] +=
            static_cast<int64_t>(started.unknown_utimes.size());
      }
      if (repair_hook_) repair_hook_(0, background_->framesTotal());
    } catch (const Error& e) {
      countRepairError(e.what());
    }
    return;
  }
  writer_->flush();  // the repair reads the store directly
  countStoreErrors();
  stats_.repair_frames_done = 0;
  stats_.repair_frames_total = static_cast<int64_t>(mapper_->trajectory().size());
  auto progress = [this](size_t done, size_t total) {
    stats_.repair_frames_done = static_cast<int64_t>(done);
    stats_.repair_frames_total = static_cast<int64_t>(total);
    if (repair_hook_) repair_hook_(stats_.repair_frames_done, stats_.repair_frames_total);
    return true;
  };
  try {
    const MapRepairResult result =
        repairMap(mapper_, options_.frame_store, correction, options_.repair, progress);
    if (!result.unknown_utimes.empty()) {
      stats_.rejected["correction: utime of no mapped frame"] +=
          static_cast<int64_t>(result.unknown_utimes.size());
    }
    recordRepair(result);
  } catch (const Error& e) {
    countRepairError(e.what());
  }
}

void MappingSession::recordRepair(const MapRepairResult& result) {
  stats_.repairs.push_back(describe(result));
  if (result.reintegration.completed) {
    try {
      options_.frame_store->recordCorrection(result.correction_id);
    } catch (const Error& e) {
      ++stats_.rejected[storeFailure(e.what())];
    }
    ++stats_.corrections_applied;
    stats_.last_correction_id = result.correction_id;
    stats_.frames_reintegrated += static_cast<int64_t>(result.reintegration.frames);
    stats_.last_repair_s = result.reintegration.seconds;
    stats_.repair_frames_done = static_cast<int64_t>(result.reintegration.frames);
    stats_.repair_frames_total = static_cast<int64_t>(result.reintegration.frames);
  } else if (!result.failure.empty()) {
    ++stats_.rejected["correction: repair failed"];
  }
}

void MappingSession::countRepairError(const std::string& what) {
  // "correction 7: none of its ... (first 123)": counted by what went wrong.
  const auto colon = what.find(": ");
  const std::string rest = colon == std::string::npos ? what : what.substr(colon + 2);
  ++stats_.rejected["correction: " + reasonOf(rest.substr(0, rest.find(" (")))];
  stats_.repairs.push_back(what);
}

void MappingSession::poll() {
  if (!background_) return;
  if (std::optional<MapRepairResult> result = background_->poll()) recordRepair(*result);
}

void MappingSession::flush() {
  if (!done_) integrate(sync_.flush());
  if (background_) {
    if (std::optional<MapRepairResult> result = background_->finish()) recordRepair(*result);
  }
  if (writer_) {
    writer_->flush();
    countStoreErrors();
  }
}

void MappingSession::recordRevertedPoses(int count) {
  writer_->flush();  // the frames are in the store before their poses change
  countStoreErrors();
  const std::vector<StampedPose>& trajectory = mapper_->trajectory();
  const size_t end = trajectory.size() - 1;  // the frame being integrated is not stored yet
  for (size_t i = end - std::min(end, static_cast<size_t>(count)); i < end; ++i) {
    try {
      options_.frame_store->updatePose(trajectory[i].utime, trajectory[i].T_W_C);
    } catch (const Error& e) {
      ++stats_.rejected["frame store: " + reasonOf(e.what())];
    }
  }
}

void MappingSession::integrate(std::vector<SyncedFrame> ready) {
  for (SyncedFrame& f : ready) {
    if (done_) return;
    try {
      if (!options_.grid_shift_m.isZero(0.0)) {
        f.T_W_C = Eigen::Translation3d(options_.grid_shift_m) * f.T_W_C;
      }
      const FrameStats s =
          mapper_->integrate(f.frame, f.T_W_C, f.panoptic ? &*f.panoptic : nullptr, f.pose_source);
      for (const auto& [stage, ms] : s.stageTimes()) times_ms_[stage].push_back(ms);
      if (s.reverted_frames > 0) {
        // The depth check found the sensor uncalibrated: the refined frames went back to their
        // given poses, so the store records those, as after a repair (this frame is stored
        // below with the pose it now has).
        refinement_moved_m_.clear();
        refinement_turned_deg_.clear();
        if (writer_) recordRevertedPoses(s.reverted_frames - 1);
      }
      if (s.tracked && !s.pose_kept) {
        refinement_moved_m_.push_back((s.T_W_C.translation() - f.T_W_C.translation()).norm());
        refinement_turned_deg_.push_back(
            Eigen::AngleAxisd(f.T_W_C.linear().transpose() * s.T_W_C.linear()).angle() * 180.0 /
            M_PI);
      }
      ++stats_.frames_integrated;
      stats_.last_frame_utime = std::max(stats_.last_frame_utime, f.frame.utime);
      if (writer_) {
        // What the mapping thread pays: a copy into the writer's queue (and a wait when the
        // disk has fallen max_queued frames behind).
        const auto start = std::chrono::steady_clock::now();
        try {
          writer_->add(f.frame, s.T_W_C, mapper_->lastPixelLabels(),
                       f.panoptic ? &*f.panoptic : nullptr,
                       f.panoptic ? mapper_->lastGeometricSegments() : GeometricSegments());
          stored_segmentation_ = stored_segmentation_ || f.panoptic.has_value();
        } catch (const Error& e) {
          ++stats_.rejected["frame store: " + reasonOf(e.what())];
        }
        countStoreErrors();
        times_ms_["frame_store"].push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count());
      }
      // The repaired map must hold every frame the live one does.
      if (background_) background_->frameIntegrated();
      if (options_.max_frames > 0 && stats_.frames_integrated >= options_.max_frames) done_ = true;
      if (hook_) {
        try {
          hook_(f, s);
        } catch (const Error& e) {
          ++stats_.rejected["after frame: " + reasonOf(e.what())];
        }
      }
    } catch (const Error& e) {
      ++stats_.rejected["frame: " + reasonOf(e.what())];
    }
    poll();
  }
}

SessionStats MappingSession::stats() const {
  SessionStats out = stats_;
  out.sync = sync_.stats();
  // Frames between two poses too far apart to interpolate have a reason of their own: the
  // setting that would map them is named by syncWarnings().
  if (out.sync.rejected_no_pose > out.sync.rejected_pose_gap) {
    out.rejected["frame: no pose"] += out.sync.rejected_no_pose - out.sync.rejected_pose_gap;
  }
  if (out.sync.rejected_pose_gap) {
    out.rejected["frame: poses around it too far apart to interpolate"] +=
        out.sync.rejected_pose_gap;
  }
  if (out.sync.dropped_queue_full) {
    out.rejected["frame: no pose while the synchroniser queue was full"] +=
        out.sync.dropped_queue_full;
  }
  const std::pair<const char*, int64_t> counted[] = {
      {"frame: repeated timestamp", out.sync.repeated_frames},
      {"frame: out of order", out.sync.out_of_order_frames},
      {"pose: repeated timestamp", out.sync.repeated_poses},
      {"panoptic: repeated timestamp", out.sync.repeated_panoptic},
      {"panoptic: arrived after its frame was mapped", out.sync.late_panoptic}};
  for (const auto& [reason, n] : counted) {
    if (n) out.rejected[reason] += n;
  }
  for (const auto& [stage, list] : times_ms_) out.timings[stage] = summariseTimes(list);
  out.refinement.frames = static_cast<int64_t>(refinement_moved_m_.size());
  out.refinement.moved_m = spreadOf(refinement_moved_m_);
  out.refinement.turned_deg = spreadOf(refinement_turned_deg_);
  if (background_ && background_->running()) {
    out.repair_running = true;
    out.repair_frames_done = background_->framesDone();
    out.repair_frames_total = background_->framesTotal();
  }
  return out;
}

std::vector<std::string> syncWarnings(const SessionStats& stats, const SyncConfig& config) {
  std::vector<std::string> out;
  const SyncStats& s = stats.sync;
  char line[320];
  // Frames without a mask are only news when masks come at all: a geometry-only run has none.
  const int64_t with_mask = s.frames_out - s.geometry_only;
  if (with_mask > 0 && s.geometry_only > 0) {
    std::snprintf(line, sizeof(line),
                  "panoptic: %lld of %lld frames mapped without a mask (a network slower than the "
                  "camera skips frames; masks late by more than sync.wait_s %.2f or stamped "
                  "more than sync.mask_tolerance_ms %.1f off their frame are not matched)",
                  static_cast<long long>(s.geometry_only), static_cast<long long>(s.frames_out),
                  config.wait_us * 1e-6, config.mask_tolerance_us * 1e-3);
    out.push_back(line);
  }
  if (s.unmatched_panoptic > 0) {
    std::string gap;
    if (s.last_unmatched_gap_us >= 0) {
      char text[96];
      std::snprintf(text, sizeof(text), " (the last one %.1f ms from the nearest frame)",
                    s.last_unmatched_gap_us * 1e-3);
      gap = text;
    }
    std::snprintf(line, sizeof(line),
                  "panoptic: %lld masks matched no frame%s: a mask's utime must be its frame's, "
                  "within sync.mask_tolerance_ms %.1f",
                  static_cast<long long>(s.unmatched_panoptic), gap.c_str(),
                  config.mask_tolerance_us * 1e-3);
    out.push_back(line);
  }
  if (s.late_panoptic > 0) {
    std::snprintf(line, sizeof(line),
                  "panoptic: %lld masks arrived after their frame was mapped (frames wait "
                  "sync.wait_s %.2f for their mask)",
                  static_cast<long long>(s.late_panoptic), config.wait_us * 1e-6);
    out.push_back(line);
  }
  if (s.rejected_pose_gap > 0) {
    std::snprintf(line, sizeof(line),
                  "pose: %lld frames refused between poses %.0f ms apart (the last), more than "
                  "sync.max_pose_gap_ms %.0f: a SLAM that sends keyframes only needs it larger",
                  static_cast<long long>(s.rejected_pose_gap), s.last_pose_gap_us * 1e-3,
                  config.max_pose_gap_us * 1e-3);
    out.push_back(line);
  }
  if (s.geometry_only_queue_full > 0) {
    std::snprintf(line, sizeof(line),
                  "frame: %lld frames went on without waiting for their mask: the synchroniser "
                  "holds sync.max_queue %zu frames",
                  static_cast<long long>(s.geometry_only_queue_full), config.max_queue);
    out.push_back(line);
  }
  return out;
}

}  // namespace panmap
