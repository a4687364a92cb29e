#pragma once

#include <cstddef>
#include <map>
#include <vector>

namespace panmap {

/// Heap bytes glibc malloc takes for a request of `bytes`: 8 bytes of chunk header, rounded up
/// to 16-byte multiples. An estimate for memory reports, not an exact count.
constexpr size_t mallocBytes(size_t bytes) { return ((bytes + 8 + 15) / 16) * 16; }

/// Heap bytes of one std::map node holding `value_bytes` of key and value: the red-black tree
/// links (32 bytes) in one malloc'd chunk.
constexpr size_t mapNodeBytes(size_t value_bytes) { return mallocBytes(32 + value_bytes); }

/// Estimated heap bytes of a std::map's nodes (not counting what the values own).
template <typename K, typename V>
size_t mapNodesBytes(const std::map<K, V>& m) {
  return m.size() * mapNodeBytes(sizeof(typename std::map<K, V>::value_type));
}

/// Heap bytes of a vector's buffer.
template <typename T>
size_t vectorBytes(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

}  // namespace panmap
