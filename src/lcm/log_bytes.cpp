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

bool nextEventFits(std::FILE* file, size_t file_bytes) {
  const long start = std::ftell(file);
  if (start < 0) return true;
  // As lcm_eventlog_read_next_event syncs: byte by byte until the last four are the magic.
  constexpr uint32_t kMagic = 0xEDA1DA01u;
  uint32_t magic = 0;
  int c = 0;
  do {
    c = std::fgetc(file);
    magic = (magic << 8) | static_cast<uint32_t>(c & 0xFF);
  } while (magic != kMagic && c != EOF);
  uint8_t header[24];
  bool fits = true;
  if (c != EOF && std::fread(header, 1, sizeof(header), file) == sizeof(header)) {
    auto be32 = [&](int at) {
      return static_cast<int32_t>((uint32_t{header[at]} << 24) | (uint32_t{header[at + 1]} << 16) |
                                  (uint32_t{header[at + 2]} << 8) | uint32_t{header[at + 3]});
    };
    const int32_t channel_bytes = be32(16), payload_bytes = be32(20);
    const long here = std::ftell(file);
    const size_t left = here < 0 || static_cast<size_t>(here) > file_bytes
                            ? 0
                            : file_bytes - static_cast<size_t>(here);
    // Negative lengths LCM refuses itself; only claims beyond the file are stopped here.
    fits = channel_bytes < 0 || payload_bytes < 0 ||
           static_cast<size_t>(channel_bytes) + static_cast<size_t>(payload_bytes) <= left;
  }
  std::clearerr(file);
  std::fseek(file, start, SEEK_SET);
  return fits;
}

}  // namespace panmap
