#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace panmap {

/// Statistics of one channel of an LCM log.
struct ChannelInfo {
  std::string channel;
  std::string type;     ///< panmap type name, "" when unknown or mixed
  size_t count = 0;     ///< events
  size_t bytes = 0;     ///< payload bytes
  size_t failures = 0;  ///< events that did not decode as a panmap type
  /// utime of the first and last message that decoded; when none did, the log's event
  /// timestamps (another clock: when the logger received them).
  int64_t first_utime = 0;
  int64_t last_utime = 0;
  std::string first_error;  ///< the first failure's reason

  /// Messages per second between the first and last utime (0 for fewer than two): the
  /// decoded messages only when two or more decoded, so that garbage on a channel, stamped
  /// by the logger's clock, neither counts nor stretches the span.
  double rateHz() const;
  /// Mean payload size, bytes.
  double meanBytes() const { return count ? static_cast<double>(bytes) / count : 0.0; }
};

/// Statistics of a whole log.
struct LogInfo {
  std::string path;
  size_t events = 0;
  bool truncated = false;             ///< bytes after the last readable event (cut or corrupt)
  size_t readable_bytes = 0;          ///< bytes up to the end of the last readable event
  size_t skipped_bytes = 0;           ///< leading garbage LCM's reader skipped to find an event
  std::vector<ChannelInfo> channels;  ///< sorted by channel name
  /// True when every event decoded and every byte of the file belongs to an event.
  bool allDecoded() const;
};

/// Reads every event of a log and checks it. Throws Error when the file cannot be opened.
/// @param deep also decode images inside frames and masks
/// @param progress called every few events with (bytes read, file size)
LogInfo inspectLog(const std::string& path, bool deep,
                   const std::function<void(size_t, size_t)>& progress = {});

/// The statistics as JSON text (for scripts).
std::string logInfoToJson(const LogInfo& info);

/// The statistics as an aligned text table.
std::string logInfoToTable(const LogInfo& info);

}  // namespace panmap
