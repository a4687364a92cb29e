#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "panmap/core/error.h"

namespace panmap {

/// Appends LCM messages to a log file (lcm::LogFile), stamping each event with a utime.
class LogWriter {
 public:
  /// Opens the log, truncating it (or appending to it, e.g. a correction after an import).
  /// Throws Error naming the path when it cannot.
  explicit LogWriter(const std::string& path, bool append = false)
      : path_(path), log_(path, append ? "a" : "w") {
    if (!log_.good()) throw Error("cannot write log " + path);
  }

  /// Encodes and appends one message on `channel` with event timestamp `utime`.
  template <typename Msg>
  void write(const std::string& channel, int64_t utime, const Msg& msg) {
    const int size = msg.getEncodedSize();
    buffer_.resize(static_cast<size_t>(size));
    if (msg.encode(buffer_.data(), 0, size) != size) throw Error("cannot encode " + channel);
    writeRaw(channel, utime, buffer_.data(), buffer_.size());
  }

  /// Appends one event with the bytes as they are (any bytes: e.g. garbage for tests).
  void writeRaw(const std::string& channel, int64_t utime, const void* data, size_t size) {
    lcm::LogEvent event;
    event.eventnum = next_event_++;
    event.timestamp = utime;
    event.channel = channel;
    event.datalen = static_cast<int32_t>(size);
    event.data = const_cast<void*>(data);
    if (log_.writeEvent(&event) != 0) throw Error("cannot write to log " + path_);
    bytes_ += size;
  }

  /// Payload bytes written so far.
  size_t bytes() const { return bytes_; }

 private:
  std::string path_;
  lcm::LogFile log_;
  std::vector<uint8_t> buffer_;
  int64_t next_event_ = 0;
  size_t bytes_ = 0;
};

}  // namespace panmap
