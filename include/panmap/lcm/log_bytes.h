#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>

namespace panmap {

/// Accounts for every byte of an LCM log while its events are read. LCM's reader
/// (lcm::LogFile::readNextEvent) skips garbage before an event and stops quietly at a cut or
/// corrupt one, so a reader that only counts events cannot tell a whole log from a damaged one:
/// each event must start where the previous one ended, and the last must end at the file's end.
class LogByteAccount {
 public:
  /// Bytes an event of this channel name and payload takes in the file (its 28-byte header,
  /// channel name and payload).
  static size_t eventBytes(size_t channel_length, int32_t payload_bytes);

  /// Records one event read, given its size and the file position right after it (ftell;
  /// ignored when negative or before the event could have started).
  void addEvent(size_t event_bytes, long end_position);

  /// Bytes up to the end of the last event read.
  size_t readableBytes() const { return readable_bytes_; }
  /// Bytes between events that belong to none (skipped by LCM's reader).
  size_t skippedBytes() const { return skipped_bytes_; }
  /// True when bytes after the last readable event remain in a file of `file_bytes`.
  bool truncated(size_t file_bytes) const { return readable_bytes_ < file_bytes; }

 private:
  size_t readable_bytes_ = 0;
  size_t skipped_bytes_ = 0;
};

/// True unless the event LCM's reader would read next from `file` (from its position, after
/// the garbage it skips) claims more payload or channel bytes than the file holds from there.
/// liblcm allocates the claimed payload plus one byte before reading it: a claim of 2^31 - 1
/// bytes overflows that and crashes it (fread into NULL), so readers ask this first and treat
/// a false as the log's damaged end. The file position is restored.
bool nextEventFits(std::FILE* file, size_t file_bytes);

}  // namespace panmap
