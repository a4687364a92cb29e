#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

namespace panmap {

/// Number of bits needed to write `value` (0 for 0).
inline int bitWidth(uint64_t value) {
  int bits = 0;
  while (bits < 64 && (value >> bits) != 0) ++bits;
  return bits;
}

/// Sorts `items` stably by key(item), an unsigned integer below 2^key_bits, in least
/// significant digit first counting passes of at most 11 bits (a digit every item shares is
/// skipped). For tens of thousands of items and more with keys of a few dozen bits it takes a
/// third to a half of std::sort's time. `scratch` is working memory (its contents are lost).
template <typename T, typename Key>
void radixSortByKey(std::vector<T>* items, std::vector<T>* scratch, int key_bits, Key key) {
  static_assert(std::is_trivially_copyable_v<T>, "items are moved with memcpy");
  constexpr int kMaxDigitBits = 11;
  const size_t n = items->size();
  if (n < 2 || key_bits <= 0) return;
  key_bits = std::min(key_bits, 64);
  const int passes = (key_bits + kMaxDigitBits - 1) / kMaxDigitBits;
  const int digit_bits = (key_bits + passes - 1) / passes;
  const size_t buckets = size_t{1} << digit_bits;
  const uint64_t digit_mask = buckets - 1;
  std::vector<uint32_t> counts(static_cast<size_t>(passes) * buckets, 0);
  for (const T& item : *items) {
    const uint64_t k = key(item);
    for (int p = 0; p < passes; ++p) ++counts[p * buckets + ((k >> (p * digit_bits)) & digit_mask)];
  }
  scratch->resize(n);
  T* from = items->data();
  T* to = scratch->data();
  for (int p = 0; p < passes; ++p) {
    uint32_t* offset = counts.data() + p * buckets;
    const int shift = p * digit_bits;
    if (offset[(key(from[0]) >> shift) & digit_mask] == n) continue;
    uint32_t sum = 0;
    for (size_t b = 0; b < buckets; ++b) {
      const uint32_t c = offset[b];
      offset[b] = sum;
      sum += c;
    }
    for (size_t i = 0; i < n; ++i) to[offset[(key(from[i]) >> shift) & digit_mask]++] = from[i];
    std::swap(from, to);
  }
  if (from != items->data()) std::memcpy(items->data(), from, n * sizeof(T));
}

}  // namespace panmap
