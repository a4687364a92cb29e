#pragma once

#include <cstddef>
#include <map>
#include <vector>

namespace panmap {

/// Heap bytes of one std::map node holding `value_bytes` of key and value: the red-black tree
/// links (32 bytes) plus glibc malloc's chunk rounding (8 bytes of header, 16-byte multiples).
/// An estimate for memory reports, not an exact count.
constexpr size_t mapNodeBytes(size_t value_bytes) {
  return ((32 + value_bytes + 8 + 15) / 16) * 16;
}

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
