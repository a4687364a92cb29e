// radixSortByKey against std::stable_sort.
#include <algorithm>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/radix_sort.h"

namespace panmap {
namespace {

struct Item {
  uint64_t key;
  uint32_t order;  // position before sorting: checks stability
};

void expectStableSorted(std::vector<Item> items, int key_bits) {
  std::vector<Item> expected = items;
  std::stable_sort(expected.begin(), expected.end(),
                   [](const Item& a, const Item& b) { return a.key < b.key; });
  std::vector<Item> scratch;
  radixSortByKey(&items, &scratch, key_bits, [](const Item& i) { return i.key; });
  ASSERT_EQ(items.size(), expected.size());
  for (size_t i = 0; i < items.size(); ++i) {
    EXPECT_EQ(items[i].key, expected[i].key) << i;
    EXPECT_EQ(items[i].order, expected[i].order) << i;
  }
}

std::vector<Item> randomItems(size_t n, uint64_t max_key, uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<uint64_t> key(0, max_key);
  std::vector<Item> items;
  for (size_t i = 0; i < n; ++i) items.push_back({key(rng), static_cast<uint32_t>(i)});
  return items;
}

TEST(RadixSort, SortsStablyForEveryKeyWidth) {
  // Few distinct keys (many equal: stability), a digit width that does not divide the key
  // width, full 64-bit keys, and keys whose high digits are all zero (skipped passes).
  expectStableSorted(randomItems(5000, 15, 1), 4);
  expectStableSorted(randomItems(20000, (uint64_t{1} << 34) - 1, 2), 34);
  expectStableSorted(randomItems(20000, UINT64_MAX, 3), 64);
  expectStableSorted(randomItems(3000, 1000, 4), 40);
}

TEST(RadixSort, SmallAndDegenerateInputs) {
  expectStableSorted({}, 8);
  expectStableSorted({{7, 0}}, 8);
  expectStableSorted({{3, 0}, {3, 1}, {3, 2}}, 2);
  expectStableSorted({{2, 0}, {1, 1}, {0, 2}}, 2);
  EXPECT_EQ(bitWidth(0), 0);
  EXPECT_EQ(bitWidth(1), 1);
  EXPECT_EQ(bitWidth(255), 8);
  EXPECT_EQ(bitWidth(256), 9);
  EXPECT_EQ(bitWidth(UINT64_MAX), 64);
}

}  // namespace
}  // namespace panmap
