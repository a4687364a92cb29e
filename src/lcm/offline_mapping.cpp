#include "panmap/lcm/offline_mapping.h"

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include <lcm/lcm-cpp.hpp>

#include "panmap/core/error.h"
#include "panmap/lcm/conversions.h"

namespace panmap {

StageTiming summariseTimes(std::vector<double> times_ms) {
  StageTiming t;
  if (times_ms.empty()) return t;
  std::sort(times_ms.begin(), times_ms.end());
  t.median_ms = times_ms[times_ms.size() / 2];
  t.p95_ms = times_ms[std::min(times_ms.size() - 1, times_ms.size() * 95 / 100)];
  return t;
}

namespace {

template <typename Msg>
bool decodeInto(const lcm::LogEvent& e, Msg* msg) {
  try {
    return msg->decode(e.data, 0, e.datalen) == e.datalen;
  } catch (const std::exception&) {
    return false;  // generated decoders can throw on absurd array lengths
  }
}

// First words of an error: the counted reason ("pose", "depth is 320x240 ...").
std::string reasonOf(const std::string& what) {
  const auto colon = what.find(':');
  return colon == std::string::npos ? what : what.substr(0, colon);
}

}  // namespace

OfflineReport mapLog(const std::string& log_path, const OfflineOptions& options, Mapper* mapper,
                     const std::function<void(size_t, size_t)>& progress) {
  struct stat st;
  if (::stat(log_path.c_str(), &st) != 0) throw Error("log " + log_path + " does not exist");
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw Error("cannot open log " + log_path);
  const auto start = std::chrono::steady_clock::now();
  OfflineReport report;
  FrameSynchronizer sync(options.sync);
  std::map<std::string, std::vector<double>> times;
  bool done = false;
  auto integrate = [&](std::vector<SyncedFrame> ready) {
    for (SyncedFrame& f : ready) {
      if (done) return;
      try {
        const FrameStats s =
            mapper->integrate(f.frame, f.T_W_C, f.panoptic ? &*f.panoptic : nullptr);
        times["segmentation"].push_back(s.segmentation_ms);
        times["superpoints"].push_back(s.superpoints_ms);
        times["integration"].push_back(s.integration_ms);
        times["graph"].push_back(s.graph_ms);
        times["total"].push_back(s.total_ms);
        ++report.frames_integrated;
        if (options.max_frames > 0 && report.frames_integrated >= options.max_frames) done = true;
      } catch (const Error& e) {
        ++report.rejected["frame: " + reasonOf(e.what())];
      }
    }
  };
  int64_t newest = INT64_MIN;
  while (!done) {
    const lcm::LogEvent* e = log.readNextEvent();
    if (!e) break;
    ++report.events;
    newest = std::max(newest, e->timestamp);
    try {
      if (e->channel == options.channel_rgbd) {
        rgbd_frame_t msg;
        if (!decodeInto(*e, &msg)) {
          ++report.rejected["malformed " + e->channel];
          continue;
        }
        sync.addFrame(fromMessage(msg));
      } else if (e->channel == options.channel_pose) {
        pose_t msg;
        if (!decodeInto(*e, &msg)) {
          ++report.rejected["malformed " + e->channel];
          continue;
        }
        sync.addPose(fromMessage(msg));
      } else if (e->channel == options.channel_panoptic) {
        panoptic_t msg;
        if (!decodeInto(*e, &msg)) {
          ++report.rejected["malformed " + e->channel];
          continue;
        }
        sync.addPanoptic(fromMessage(msg));
      } else {
        continue;
      }
    } catch (const Error& error) {
      ++report.rejected["bad " + e->channel + ": " + reasonOf(error.what())];
      continue;
    }
    integrate(sync.popReady(newest));
    if (progress && report.events % 8 == 0) {
      progress(static_cast<size_t>(std::ftell(log.getFilePtr())), static_cast<size_t>(st.st_size));
    }
  }
  if (!done) integrate(sync.flush());
  if (progress) progress(static_cast<size_t>(st.st_size), static_cast<size_t>(st.st_size));
  report.sync = sync.stats();
  if (report.sync.rejected_no_pose)
    report.rejected["frame: no pose"] += report.sync.rejected_no_pose;
  if (report.sync.dropped_queue_full)
    report.rejected["frame: queue full"] += report.sync.dropped_queue_full;
  for (auto& [stage, list] : times) report.timings[stage] = summariseTimes(list);
  report.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace panmap
