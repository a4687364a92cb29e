#include "panmap/graph/internal/edge_table.h"

#include <algorithm>
#include <cstdint>

#include <absl/container/flat_hash_set.h>

#include "panmap/core/container_memory.h"
#include "panmap/core/radix_sort.h"

namespace panmap {

void EdgeTable::addTo(Classes* classes, int32_t cls, double value) {
  auto it =
      std::lower_bound(classes->begin(), classes->end(), cls,
                       [](const std::pair<int32_t, double>& c, int32_t x) { return c.first < x; });
  // Starting from 0.0 and adding keeps the sums bit-identical to map[cls] += value.
  if (it == classes->end() || it->first != cls) it = classes->insert(it, {cls, 0.0});
  it->second += value;
}

const EdgeTable::Classes* EdgeTable::find(int32_t a, int32_t b) const {
  const auto it = table_.find(key(a, b));
  return it == table_.end() ? nullptr : &it->second;
}

void EdgeTable::applyMerges(const std::vector<SuperpointMerge>& merges, size_t begin, size_t end) {
  if (begin >= end) return;
  absl::flat_hash_set<int32_t> removed;
  for (size_t m = begin; m < end; ++m) removed.insert(merges[m].removed);
  auto touchesRemoved = [&removed](int32_t a, int32_t b) {
    return removed.count(a) != 0 || removed.count(b) != 0;
  };
  // Every edge with a removed end leaves the table (one pass); the merges are replayed on those
  // few, and the edges they end up on between live super-points go back. An edge lives either
  // in the table or in `pulled` throughout, so each sum is the one a merge-by-merge pass makes.
  std::map<uint64_t, Classes> pulled;
  for (auto it = table_.begin(); it != table_.end();) {
    if (touchesRemoved(first(it->first), second(it->first))) {
      pulled.emplace(it->first, std::move(it->second));
      table_.erase(it++);  // erasing leaves the other iterators valid
    } else {
      ++it;
    }
  }
  std::vector<std::pair<int32_t, Classes>> moved;  // (other end, classes)
  for (size_t m = begin; m < end; ++m) {
    const int32_t kept = merges[m].kept, gone = merges[m].removed;
    moved.clear();
    for (auto it = pulled.begin(); it != pulled.end();) {
      const int32_t a = first(it->first), b = second(it->first);
      if (a != gone && b != gone) {
        ++it;
        continue;
      }
      const int32_t other = a == gone ? b : a;
      if (other != kept) moved.emplace_back(other, std::move(it->second));
      it = pulled.erase(it);
    }
    // One source per target pair, so the order of the moves does not change any sum.
    for (const auto& [other, classes] : moved) {
      const auto [lo, hi] = std::minmax(kept, other);
      Classes* target = touchesRemoved(lo, hi) ? &pulled[key(lo, hi)] : &table_[key(lo, hi)];
      for (const auto& [cls, c] : classes) addTo(target, cls, c);
    }
  }
  // Only left when a removed label was kept again later, as a merge-by-merge pass keeps it.
  for (auto& [k, classes] : pulled) table_[k] = std::move(classes);
}

void EdgeTable::rename(const std::function<int32_t(int32_t)>& to) {
  absl::flat_hash_map<uint64_t, Classes> renamed;
  renamed.reserve(table_.size());
  for (auto& [k, classes] : table_) {
    const int32_t a = to(first(k)), b = to(second(k));
    if (a <= 0 || b <= 0 || a == b) continue;
    // Distinct ends stay distinct, so no two pairs meet and no sum depends on the order.
    renamed.emplace(key(std::min(a, b), std::max(a, b)), std::move(classes));
  }
  table_ = std::move(renamed);
}

void EdgeTable::keepIf(const std::function<bool(int32_t)>& keep) {
  for (auto it = table_.begin(); it != table_.end();) {
    if (keep(first(it->first)) && keep(second(it->first))) {
      ++it;
    } else {
      table_.erase(it++);
    }
  }
}

size_t EdgeTable::keepPairsIf(const std::function<bool(int32_t, int32_t, const Classes&)>& keep) {
  size_t dropped = 0;
  for (auto it = table_.begin(); it != table_.end();) {
    if (keep(first(it->first), second(it->first), it->second)) {
      ++it;
    } else {
      table_.erase(it++);
      ++dropped;
    }
  }
  return dropped;
}

void EdgeTable::forEachSorted(
    const std::function<void(int32_t, int32_t, const Classes&)>& f) const {
  // Keys beside the pointers: sorting them does not reach into the table's scattered slots
  // (a building's table holds 300k pairs, far more than the cache).
  struct Entry {
    uint64_t key;
    const Classes* classes;
  };
  std::vector<Entry> entries, scratch;
  entries.reserve(table_.size());
  uint32_t lo[2] = {UINT32_MAX, UINT32_MAX}, hi[2] = {0, 0};
  for (const auto& [key, classes] : table_) {
    entries.push_back({key, &classes});
    const uint32_t half[2] = {static_cast<uint32_t>(key >> 32), static_cast<uint32_t>(key)};
    for (int i = 0; i < 2; ++i) {
      lo[i] = std::min(lo[i], half[i]);
      hi[i] = std::max(hi[i], half[i]);
    }
  }
  if (!entries.empty()) {
    // Keys are distinct, so any sort gives one order: the halves' offsets from their minima,
    // side by side, are a few dozen bits for counting passes.
    const int low_bits = bitWidth(hi[1] - lo[1]);
    const int bits = bitWidth(hi[0] - lo[0]) + low_bits;
    const uint64_t first_lo = lo[0], second_lo = lo[1];
    radixSortByKey(&entries, &scratch, bits, [=](const Entry& e) {
      return ((e.key >> 32) - first_lo) << low_bits | ((e.key & 0xFFFFFFFFu) - second_lo);
    });
  }
  for (const Entry& e : entries) f(first(e.key), second(e.key), *e.classes);
}

EdgeTable::OrderedEdges EdgeTable::toOrdered() const {
  OrderedEdges out;
  forEachSorted([&out](int32_t a, int32_t b, const Classes& classes) {
    out.emplace_hint(out.end(), std::make_pair(a, b),
                     std::map<int32_t, double>(classes.begin(), classes.end()));
  });
  return out;
}

void EdgeTable::assign(const OrderedEdges& edges) {
  table_.clear();
  table_.reserve(edges.size());
  for (const auto& [pair, classes] : edges) {
    Classes& target = table_[key(pair.first, pair.second)];
    target.assign(classes.begin(), classes.end());
  }
}

size_t EdgeTable::memoryBytes() const {
  using Slot = std::pair<const uint64_t, Classes>;
  size_t bytes = table_.capacity() * (sizeof(Slot) + 1);
  for (const auto& entry : table_) {
    // Pairs seen under more than one class keep their classes on the heap.
    if (entry.second.capacity() > 1) {
      bytes += mallocBytes(entry.second.capacity() * sizeof(Classes::value_type));
    }
  }
  return bytes;
}

}  // namespace panmap
