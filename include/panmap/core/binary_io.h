#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "panmap/core/error.h"

namespace panmap {

/// Appends plain values to a byte buffer (little-endian host layout, as written).
class BinaryWriter {
 public:
  /// Appends a trivially copyable value.
  template <typename T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    const auto* p = reinterpret_cast<const uint8_t*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  /// Appends raw bytes.
  void putBytes(const void* data, size_t size) {
    const auto* p = static_cast<const uint8_t*>(data);
    bytes_.insert(bytes_.end(), p, p + size);
  }
  /// Appends a length-prefixed string.
  void putString(const std::string& s) {
    put<uint64_t>(s.size());
    putBytes(s.data(), s.size());
  }
  /// The bytes so far.
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  std::vector<uint8_t> bytes_;
};

/// Reads plain values back, refusing to read past the end (Error naming `what`).
class BinaryReader {
 public:
  /// @param what names the source in error messages (e.g. the file)
  BinaryReader(const uint8_t* data, size_t size, std::string what)
      : data_(data), size_(size), what_(std::move(what)) {}
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
                  std::to_string(pos_) + ")");
    // memcpy with a null pointer is undefined even for 0 bytes (an empty vector's data()).
    if (size == 0) return;
    std::memcpy(out, data_ + pos_, size);
    pos_ += size;
  }
  /// Reads a count and checks that at least count * min_item_bytes remain (so corrupt counts
  /// fail cleanly instead of allocating gigabytes).
  uint64_t getCount(size_t min_item_bytes) {
    const uint64_t n = get<uint64_t>();
    if (min_item_bytes > 0 && n > (size_ - pos_) / min_item_bytes) {
      throw Error(what_ + ": corrupt count " + std::to_string(n) + " at offset " +
                  std::to_string(pos_));
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

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  std::string what_;
};

}  // namespace panmap
