#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <string>

#include "panmap/lcm/mapping_session.h"

namespace panmap {

/// What an offline run did.
struct OfflineReport : SessionStats {
  int64_t events = 0;  ///< log events read (every channel)
  double wall_s = 0.0;
  size_t log_bytes = 0;        ///< size of the log file
  size_t readable_bytes = 0;   ///< bytes up to the end of the last event LCM's reader gave
  size_t skipped_bytes = 0;    ///< bytes between events that belong to none
  bool stopped_early = false;  ///< SessionOptions::max_frames reached before the log's end
  std::map<std::string, int64_t> channel_events;  ///< events read, by channel
};

/// What is wrong with the log itself, in one line ("" when every byte belonged to an event):
/// a cut or corrupt tail (LCM's reader stops there quietly; not looked for when the run
/// stopped early) or garbage between events.
std::string describeLogDamage(const OfflineReport& report);

/// Why a run mapped no frame, in one line: an empty file, no LCM event at all, no event on the
/// input channels (naming the channels the log has), or the refusals of every frame received.
std::string describeNothingMapped(const OfflineReport& report, const SessionOptions& options);

/// A log whose masks went unread, in one line ("" otherwise): no event on the panoptic channel
/// while the log has channels the mapper does not read (naming them, e.g. masks logged as
/// "panoptic" for a mapper listening on "PANOPTIC").
std::string describeUnreadChannels(const OfflineReport& report, const SessionOptions& options);

/// Maps every frame of a log as fast as possible, in log order, through a MappingSession
/// (stream time = the log's event timestamps). Deterministic.
/// @param progress called with (bytes read, log size) every few events
/// @param hook called after every integrated frame
OfflineReport mapLog(const std::string& log_path, const SessionOptions& options, Mapper* mapper,
                     const std::function<void(size_t, size_t)>& progress = {},
                     const MappingSession::FrameHook& hook = {});

}  // namespace panmap
