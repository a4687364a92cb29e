#pragma once

#include <cstddef>
#include <exception>

namespace panmap {

/// Decodes an lcm-gen message that must fill exactly `size` bytes. False for truncated,
/// malformed or over-long data; never throws (generated decoders can throw on absurd array
/// lengths), so it is safe inside LCM callbacks.
template <typename Msg>
bool decodeExactly(const void* data, size_t size, Msg* msg) {
  try {
    return msg->decode(data, 0, static_cast<int>(size)) == static_cast<int>(size);
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace panmap
