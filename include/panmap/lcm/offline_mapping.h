#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "panmap/mapper/frame_sync.h"
#include "panmap/mapper/mapper.h"

namespace panmap {

/// Channels and options of a mapping run over an LCM log.
struct OfflineOptions {
  std::string channel_rgbd = "CAMERA_RGBD";
  std::string channel_pose = "CAMERA_POSE";
  std::string channel_panoptic = "PANOPTIC";
  SyncConfig sync;
  int64_t max_frames = 0;  ///< stop after this many integrated frames (0 = all)
};

/// Median and 95th percentile of a stage's per-frame time.
struct StageTiming {
  double median_ms = 0.0;
  double p95_ms = 0.0;
};

/// What an offline run did.
struct OfflineReport {
  int64_t events = 0;
  int64_t frames_integrated = 0;
  std::map<std::string, int64_t> rejected;  ///< reason -> frames (or messages) refused
  SyncStats sync;
  std::map<std::string, StageTiming> timings;  ///< by stage name
  double wall_s = 0.0;
};

/// Maps every frame of a log as fast as possible, in log order: decodes messages (counting
/// malformed ones), synchronises frames with poses and masks, and integrates them. Bad input
/// is refused with a counted reason; the map is never touched by it. Deterministic.
/// @param progress called with (bytes read, log size) every few frames
OfflineReport mapLog(const std::string& log_path, const OfflineOptions& options, Mapper* mapper,
                     const std::function<void(size_t, size_t)>& progress = {});

/// Median / p95 of a list of times.
StageTiming summariseTimes(std::vector<double> times_ms);

}  // namespace panmap
