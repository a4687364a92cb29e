#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "panmap/lcm/mapping_session.h"

namespace panmap {

/// What an offline run did.
struct OfflineReport : SessionStats {
  int64_t events = 0;  ///< log events read (every channel)
  double wall_s = 0.0;
};

/// Maps every frame of a log as fast as possible, in log order, through a MappingSession
/// (stream time = the log's event timestamps). Deterministic.
/// @param progress called with (bytes read, log size) every few events
/// @param hook called after every integrated frame
OfflineReport mapLog(const std::string& log_path, const SessionOptions& options, Mapper* mapper,
                     const std::function<void(size_t, size_t)>& progress = {},
                     const MappingSession::FrameHook& hook = {});

}  // namespace panmap
