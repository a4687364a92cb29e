#pragma once

// 64-bit FNV-1a fingerprints: a test pins the value measured before a change, and a benchmark
// prints one, to show that a change left an output bit for bit as it was.

#include <cstddef>
#include <cstdint>

namespace panmap {

/// FNV-1a over raw bytes.
class Fingerprint {
 public:
  /// Mixes in `n` bytes at `data`.
  void add(const void* data, size_t n) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) {
      hash_ ^= b[i];
      hash_ *= 1099511628211ull;
    }
  }
  /// The fingerprint so far.
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 1469598103934665603ull;
};

}  // namespace panmap
