#include "panmap/lcm/log_bytes.h"

namespace panmap {

size_t LogByteAccount::eventBytes(size_t channel_length, int32_t payload_bytes) {
  // Sync word (4), event number (8), timestamp (8), channel length (4), payload length (4).
  constexpr size_t kHeaderBytes = 28;
  return kHeaderBytes + channel_length + static_cast<size_t>(payload_bytes < 0 ? 0 : payload_bytes);
}

void LogByteAccount::addEvent(size_t event_bytes, long end_position) {
  if (end_position < 0 || static_cast<size_t>(end_position) < event_bytes) return;
  const size_t end = static_cast<size_t>(end_position);
  const size_t start = end - event_bytes;
  if (start > readable_bytes_) skipped_bytes_ += start - readable_bytes_;
  readable_bytes_ = end;
}

}  // namespace panmap
