// LCM's wire format starts with the type's 8-byte fingerprint (big-endian). The LCM targets
// put the right one in front of the fuzzed body, so that mutations are spent on the fields
// rather than on guessing 64-bit constants.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace panmap {
namespace fuzz {

/// The fingerprint of T followed by `size` bytes of body.
template <typename T>
std::vector<uint8_t> withFingerprint(const uint8_t* body, size_t size) {
  std::vector<uint8_t> bytes(8 + size);
  const uint64_t hash = static_cast<uint64_t>(T::getHash());
  for (int i = 0; i < 8; ++i) bytes[i] = static_cast<uint8_t>(hash >> (56 - 8 * i));
  if (size > 0) std::copy(body, body + size, bytes.begin() + 8);
  return bytes;
}

}  // namespace fuzz
}  // namespace panmap
