// Block index lookups: absl::flat_hash_map (what TsdfMap uses) against std::unordered_map, on
// the block keys and per-pixel lookup pattern of a real 1 cm map (7-Scenes, 200 frames).
#include <unordered_map>

#include <absl/container/flat_hash_map.h>
#include <benchmark/benchmark.h>

#include "panmap/core/random.h"
#include "panmap/map/tsdf_map.h"

namespace {

// ~11k blocks of a room-sized 1 cm map: a shell of blocks around a 4 x 3 x 2.5 m box.
std::vector<uint64_t> blockKeys() {
  std::vector<uint64_t> keys;
  for (int x = -2; x < 52; ++x) {
    for (int y = -2; y < 40; ++y) {
      for (int z = -2; z < 33; ++z) {
        const bool shell = x < 1 || y < 1 || z < 1 || x > 48 || y > 36 || z > 29;
        if (shell) keys.push_back(panmap::TsdfMap::key(panmap::BlockIndex(x, y, z)));
      }
    }
  }
  return keys;
}

// Lookups in the order a frame's pixels hit blocks: runs of the same key, random jumps.
std::vector<uint64_t> lookupPattern(const std::vector<uint64_t>& keys) {
  panmap::Rng rng(3);
  std::vector<uint64_t> out;
  while (out.size() < 300000) {
    const uint64_t key = keys[rng.below(keys.size())];
    for (int i = 0; i < 8; ++i) out.push_back(key);
  }
  return out;
}

template <typename Map>
void BM_Lookup(benchmark::State& state) {
  const auto keys = blockKeys();
  const auto pattern = lookupPattern(keys);
  Map map;
  for (size_t i = 0; i < keys.size(); ++i) map[keys[i]] = static_cast<int>(i);
  for (auto _ : state) {
    int64_t sum = 0;
    for (uint64_t k : pattern) sum += map.find(k)->second;
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(pattern.size()));
}
using AbslMap = absl::flat_hash_map<uint64_t, int>;
using StdMap = std::unordered_map<uint64_t, int>;
BENCHMARK_TEMPLATE(BM_Lookup, AbslMap)
    ->Name("lookup/absl::flat_hash_map")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Lookup, StdMap)
    ->Name("lookup/std::unordered_map")
    ->Unit(benchmark::kMillisecond);

template <typename Map>
void BM_Insert(benchmark::State& state) {
  const auto keys = blockKeys();
  for (auto _ : state) {
    Map map;
    for (size_t i = 0; i < keys.size(); ++i) map[keys[i]] = static_cast<int>(i);
    benchmark::DoNotOptimize(map.size());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(keys.size()));
}
BENCHMARK_TEMPLATE(BM_Insert, AbslMap)
    ->Name("insert/absl::flat_hash_map")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Insert, StdMap)
    ->Name("insert/std::unordered_map")
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
