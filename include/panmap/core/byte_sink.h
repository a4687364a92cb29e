#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace panmap {

/// Where a streaming BinaryWriter puts its bytes: a file, a buffer, a checksum.
class ByteSink {
 public:
  virtual ~ByteSink() = default;
  /// Appends bytes at the end.
  virtual void append(const uint8_t* data, size_t size) = 0;
  /// Replaces bytes appended earlier (e.g. a size only known at the end).
  virtual void overwrite(uint64_t offset, const uint8_t* data, size_t size) = 0;
};

/// A sink into a byte vector.
class VectorSink : public ByteSink {
 public:
  /// @param out receives the bytes (not owned)
  explicit VectorSink(std::vector<uint8_t>* out) : out_(out) {}
  /// Appends to the vector.
  void append(const uint8_t* data, size_t size) override;
  /// Replaces bytes of the vector; throws Error past its end.
  void overwrite(uint64_t offset, const uint8_t* data, size_t size) override;

 private:
  std::vector<uint8_t>* out_;
};

}  // namespace panmap
