#include "panmap/lcm/offline_mapping.h"

#include <sys/stat.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "panmap/core/error.h"
#include "panmap/lcm/log_bytes.h"

namespace panmap {

OfflineReport mapLog(const std::string& log_path, const SessionOptions& options, Mapper* mapper,
                     const std::function<void(size_t, size_t)>& progress,
                     const MappingSession::FrameHook& hook) {
  struct stat st;
  if (::stat(log_path.c_str(), &st) != 0) throw Error("log " + log_path + " does not exist");
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw Error("cannot open log " + log_path);
  const auto start = std::chrono::steady_clock::now();
  MappingSession session(options, mapper);
  if (hook) session.setFrameHook(hook);
  int64_t events = 0;
  LogByteAccount bytes;
  std::map<std::string, int64_t> channel_events;
  while (!session.done()) {
    // A header claiming more bytes than are left is the damaged end (and would crash liblcm).
    if (!nextEventFits(log.getFilePtr(), static_cast<size_t>(st.st_size))) break;
    const lcm::LogEvent* e = log.readNextEvent();
    if (!e) break;
    ++events;
    bytes.addEvent(LogByteAccount::eventBytes(e->channel.size(), e->datalen),
                   std::ftell(log.getFilePtr()));
    ++channel_events[e->channel];
    // Waits run on the messages' own utimes, as live: the logger's clock (event timestamps)
    // may be another, and any channel's events advanced it.
    session.handle(e->channel, e->data, static_cast<size_t>(e->datalen));
    if (progress && events % 8 == 0) {
      progress(static_cast<size_t>(std::ftell(log.getFilePtr())), static_cast<size_t>(st.st_size));
    }
  }
  const bool stopped_early = session.done();  // before flush(), which may reach max_frames
  session.flush();
  if (progress) progress(static_cast<size_t>(st.st_size), static_cast<size_t>(st.st_size));
  OfflineReport report;
  static_cast<SessionStats&>(report) = session.stats();
  report.events = events;
  report.log_bytes = static_cast<size_t>(st.st_size);
  report.readable_bytes = bytes.readableBytes();
  report.skipped_bytes = bytes.skippedBytes();
  report.channel_events = std::move(channel_events);
  report.stopped_early = stopped_early;
  report.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

std::string describeLogDamage(const OfflineReport& report) {
  std::string out;
  if (!report.stopped_early && report.readable_bytes < report.log_bytes) {
    out = "unreadable after byte " + std::to_string(report.readable_bytes) + " of " +
          std::to_string(report.log_bytes) + " (truncated or corrupt)";
  }
  if (report.skipped_bytes > 0) {
    out += (out.empty() ? "" : "; ") + std::to_string(report.skipped_bytes) +
           " bytes between events are not events";
  }
  return out;
}

std::string describeUnreadChannels(const OfflineReport& report, const SessionOptions& options) {
  if (report.channel_events.count(options.channel_panoptic) > 0) return "";
  std::string unread;
  for (const auto& [channel, count] : report.channel_events) {
    if (channel == options.channel_rgbd || channel == options.channel_pose ||
        channel == options.channel_correction) {
      continue;
    }
    unread += (unread.empty() ? "" : ", ") + channel + " (" + std::to_string(count) + ")";
  }
  if (unread.empty()) return "";
  return "no event on the panoptic channel " + options.channel_panoptic +
         ", so every frame was mapped without masks; the log also has " + unread +
         ", which no option names (--channel-panoptic)";
}

std::string describeNothingMapped(const OfflineReport& report, const SessionOptions& options) {
  if (report.log_bytes == 0) return "the log is empty";
  if (report.events == 0) return "no LCM event in the log (not an LCM log, or corrupt from byte 0)";
  if (report.channel_events.count(options.channel_rgbd) == 0) {
    std::string channels;
    for (const auto& [channel, count] : report.channel_events) {
      channels += (channels.empty() ? "" : ", ") + channel + " (" + std::to_string(count) + ")";
    }
    return "no event on the RGB-D channel " + options.channel_rgbd + "; the log has " + channels;
  }
  std::string refused;
  for (const auto& [reason, count] : report.rejected) {
    refused += (refused.empty() ? "" : ", ") + reason + " (" + std::to_string(count) + ")";
  }
  return std::to_string(report.channel_events.at(options.channel_rgbd)) + " events on " +
         options.channel_rgbd + ", no frame integrated" +
         (refused.empty() ? std::string() : "; refused: " + refused);
}

}  // namespace panmap
