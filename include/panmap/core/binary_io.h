#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "panmap/core/byte_sink.h"
#include "panmap/core/error.h"

namespace panmap {

/// Appends plain values to a byte buffer (little-endian host layout, as written). With a sink,
/// the buffer is handed over in chunks as it fills, so large outputs (map files) stream to
/// disk instead of being held whole in memory.
class BinaryWriter {
 public:
  /// Keeps everything in memory (bytes()).
  BinaryWriter() = default;
  /// Streams to `sink` (not owned) in chunks of about `chunk_bytes`; call flush() at the end.
  explicit BinaryWriter(ByteSink* sink, size_t chunk_bytes = size_t{1} << 20)
      : sink_(sink), chunk_bytes_(chunk_bytes) {
    bytes_.reserve(chunk_bytes_);
  }
  /// Appends a trivially copyable value.
  template <typename T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    putBytes(&value, sizeof(T));
  }
  /// Appends raw bytes.
  void putBytes(const void* data, size_t size) {
    const auto* p = static_cast<const uint8_t*>(data);
    bytes_.insert(bytes_.end(), p, p + size);
    if (sink_ && bytes_.size() >= chunk_bytes_) flush();
  }
  /// Appends a length-prefixed string.
  void putString(const std::string& s) {
    put<uint64_t>(s.size());
    putBytes(s.data(), s.size());
  }
  /// Overwrites a value written earlier at `offset` (e.g. a size known only at the end).
  template <typename T>
  void putAt(size_t offset, const T& value) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    if (offset + sizeof(T) > size()) throw Error("BinaryWriter::putAt past the end");
    const auto* p = reinterpret_cast<const uint8_t*>(&value);
    if (offset >= flushed_) {
      std::memcpy(bytes_.data() + (offset - flushed_), p, sizeof(T));
    } else {
      flush();
      sink_->overwrite(offset, p, sizeof(T));
    }
  }
  /// Hands what is buffered to the sink (no-op without one).
  void flush() {
    if (!sink_ || bytes_.empty()) return;
    sink_->append(bytes_.data(), bytes_.size());
    flushed_ += bytes_.size();
    bytes_.clear();
  }
  /// Bytes written so far, flushed or not.
  size_t size() const { return flushed_ + bytes_.size(); }
  /// The bytes so far (without a sink: all of them).
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  std::vector<uint8_t> bytes_;
  ByteSink* sink_ = nullptr;
  size_t chunk_bytes_ = 0;
  size_t flushed_ = 0;
};

/// Where a streaming BinaryReader pulls its bytes from: a file, a checksum.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  /// Copies the next `size` bytes into `out`; throws Error when they cannot all be read.
  virtual void read(uint8_t* out, size_t size) = 0;
};

/// Reads plain values back, refusing to read past the end (Error naming `what`). Either over a
/// buffer held in memory, or streamed from a ByteSource through a small window, so that a large
/// input (a map file) never has to be held whole in memory.
class BinaryReader {
 public:
  /// Reads `size` bytes held in memory.
  /// @param what names the source in error messages (e.g. the file)
  /// @param base_offset where `data` starts in that source, so errors name source offsets
  BinaryReader(const uint8_t* data, size_t size, std::string what, size_t base_offset = 0)
      : data_(data), size_(size), window_end_(size), what_(std::move(what)), base_(base_offset) {}
  /// Streams `size` bytes from `source` (not owned) through a window of `window_bytes`.
  BinaryReader(ByteSource* source, size_t size, std::string what, size_t base_offset = 0,
               size_t window_bytes = size_t{1} << 20)
      : size_(size),
        what_(std::move(what)),
        base_(base_offset),
        source_(source),
        window_(std::max<size_t>(window_bytes, 1)) {}
  /// Reads a trivially copyable value.
  template <typename T>
  T get() {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    T value;
    getBytes(&value, sizeof(T));
    return value;
  }
  /// Reads raw bytes.
  void getBytes(void* out, size_t size) {
    if (size > size_ - pos_)
      throw Error(what_ + ": truncated (needs " + std::to_string(size) + " more bytes at offset " +
                  std::to_string(base_ + pos_) + ")");
    // memcpy with a null pointer is undefined even for 0 bytes (an empty vector's data()).
    if (size == 0) return;
    if (size <= window_end_ - pos_) {
      std::memcpy(out, data_ + (pos_ - window_start_), size);
      pos_ += size;
      return;
    }
    refill(static_cast<uint8_t*>(out), size);
  }
  /// Reads a count and checks that at least count * min_item_bytes remain (so corrupt counts
  /// fail cleanly instead of allocating gigabytes).
  uint64_t getCount(size_t min_item_bytes) {
    const uint64_t n = get<uint64_t>();
    if (min_item_bytes > 0 && n > (size_ - pos_) / min_item_bytes) {
      throw Error(what_ + ": corrupt count " + std::to_string(n) + " at offset " +
                  std::to_string(base_ + pos_ - sizeof(uint64_t)));
    }
    return n;
  }
  /// Reads a length-prefixed string.
  std::string getString() {
    const uint64_t n = getCount(1);
    std::string s(n, '\0');
    getBytes(s.data(), n);
    return s;
  }
  /// Bytes not read yet.
  size_t remaining() const { return size_ - pos_; }
  /// Reads and drops what is left (a streamed source is then read to its end, e.g. so that a
  /// checksum over it is complete).
  void skipRest() {
    uint8_t scratch[4096];
    while (remaining() > 0) getBytes(scratch, std::min(sizeof(scratch), remaining()));
  }

 private:
  // The slow path of a streamed read: what the window holds, then whole reads straight into
  // `out` for large requests, else a new window. Only reached with a source: in memory the
  // window is the whole buffer and getBytes() checked the size.
  void refill(uint8_t* out, size_t size) {
    const size_t held = window_end_ - pos_;
    if (held > 0) std::memcpy(out, data_ + (pos_ - window_start_), held);
    out += held;
    size -= held;
    pos_ += held;
    if (size >= window_.size()) {
      source_->read(out, size);
      pos_ += size;
      window_start_ = window_end_ = pos_;
      return;
    }
    const size_t n = std::min(window_.size(), size_ - pos_);
    source_->read(window_.data(), n);
    data_ = window_.data();
    window_start_ = pos_;
    window_end_ = pos_ + n;
    std::memcpy(out, data_, size);
    pos_ += size;
  }

  const uint8_t* data_ = nullptr;  // the window's bytes: source bytes window_start_ onwards
  size_t size_;
  size_t pos_ = 0;
  size_t window_start_ = 0, window_end_ = 0;
  std::string what_;
  size_t base_ = 0;
  ByteSource* source_ = nullptr;
  std::vector<uint8_t> window_;
};

}  // namespace panmap
