// ThreadPool: which ranges fn sees, how often, and with which slice index.
#include <algorithm>
#include <atomic>
#include <mutex>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/thread_pool.h"

namespace panmap {
namespace {

using Call = std::tuple<size_t, size_t, int>;  // begin, end, thread

// Every call parallelFor makes for n indices, sorted by begin.
std::vector<Call> callsOf(ThreadPool* pool, size_t n) {
  std::mutex mutex;
  std::vector<Call> calls;
  pool->parallelFor(n, [&](size_t begin, size_t end, int thread) {
    std::lock_guard<std::mutex> lock(mutex);
    calls.emplace_back(begin, end, thread);
  });
  std::sort(calls.begin(), calls.end());
  return calls;
}

TEST(ThreadPool, SlicesAreStaticAndEachThreadGetsItsOwn) {
  ThreadPool pool(3);
  EXPECT_EQ(pool.size(), 3);
  // n * t / 3 for t = 0..3: 0, 3, 6, 10.
  EXPECT_EQ(callsOf(&pool, 10), (std::vector<Call>{{0, 3, 0}, {3, 6, 1}, {6, 10, 2}}));
  // Fewer indices than threads: empty slices are not called.
  EXPECT_EQ(callsOf(&pool, 2), (std::vector<Call>{{0, 1, 1}, {1, 2, 2}}));
  // One index or none: the caller alone, or no call.
  EXPECT_EQ(callsOf(&pool, 1), (std::vector<Call>{{0, 1, 0}}));
  EXPECT_TRUE(callsOf(&pool, 0).empty());
}

TEST(ThreadPool, OneThreadRunsTheWholeRangeInTheCaller) {
  ThreadPool pool(1);
  EXPECT_EQ(pool.size(), 1);
  const std::thread::id caller = std::this_thread::get_id();
  std::thread::id ran_on;
  pool.parallelFor(7, [&](size_t begin, size_t end, int thread) {
    EXPECT_EQ(begin, 0u);
    EXPECT_EQ(end, 7u);
    EXPECT_EQ(thread, 0);
    ran_on = std::this_thread::get_id();
  });
  EXPECT_EQ(ran_on, caller);
}

TEST(ThreadPool, ManyShortRangesInARowEachCoverEveryIndexOnce) {
  // A frame runs a dozen short ranges back to back: a lost wake-up or a job read after it
  // ended shows as a hang or a miscount here.
  ThreadPool pool(4);
  std::vector<std::atomic<int>> hits(64);
  for (int round = 0; round < 5000; ++round) {
    const size_t n = 1 + static_cast<size_t>(round) % hits.size();
    pool.parallelFor(n, [&](size_t begin, size_t end, int) {
      for (size_t i = begin; i < end; ++i) hits[i].fetch_add(1, std::memory_order_relaxed);
    });
  }
  // Index i is in the range of every round whose n is above i.
  for (size_t i = 0; i < hits.size(); ++i) {
    int expected = 0;
    for (int round = 0; round < 5000; ++round) {
      if (1 + static_cast<size_t>(round) % hits.size() > i) ++expected;
    }
    EXPECT_EQ(hits[i].load(), expected) << "index " << i;
  }
}

TEST(ThreadPool, DynamicChunksCoverEveryIndexOnceInGrains) {
  ThreadPool pool(3);
  std::vector<int> hits(1000, 0);
  std::mutex mutex;
  std::vector<std::pair<size_t, size_t>> chunks;
  std::atomic<bool> bad_thread{false};
  pool.parallelForDynamic(hits.size(), 64, [&](size_t begin, size_t end, int thread) {
    if (thread < 0 || thread >= pool.size()) bad_thread = true;
    for (size_t i = begin; i < end; ++i) ++hits[i];  // chunks are disjoint: no race
    std::lock_guard<std::mutex> lock(mutex);
    chunks.emplace_back(begin, end);
  });
  EXPECT_FALSE(bad_thread.load());
  EXPECT_EQ(std::count(hits.begin(), hits.end(), 1), 1000);
  std::sort(chunks.begin(), chunks.end());
  ASSERT_EQ(chunks.size(), 16u);  // 15 grains of 64 and the last 40
  for (size_t c = 0; c < chunks.size(); ++c) {
    EXPECT_EQ(chunks[c].first, 64 * c);
    EXPECT_EQ(chunks[c].second, std::min<size_t>(64 * (c + 1), 1000));
  }
  // A range no longer than one grain runs in the caller in one call.
  std::vector<Call> calls;
  pool.parallelForDynamic(64, 64, [&](size_t b, size_t e, int t) { calls.emplace_back(b, e, t); });
  EXPECT_EQ(calls, (std::vector<Call>{{0, 64, 0}}));
}

TEST(ThreadPool, TwoPoolsUsedAtOnceFromTwoThreadsEachGetTheirOwnResults) {
  // A repair's pool beside the live mapper's: more threads than cores, each pool its own jobs.
  ThreadPool a(2), b(2);
  auto sumWith = [](ThreadPool* pool, uint64_t* out) {
    uint64_t total = 0;
    for (int round = 0; round < 2000; ++round) {
      std::vector<uint64_t> parts(static_cast<size_t>(pool->size()), 0);
      pool->parallelFor(100, [&](size_t begin, size_t end, int thread) {
        for (size_t i = begin; i < end; ++i) parts[static_cast<size_t>(thread)] += i;
      });
      for (uint64_t p : parts) total += p;
    }
    *out = total;
  };
  uint64_t sum_a = 0, sum_b = 0;
  std::thread other([&] { sumWith(&b, &sum_b); });
  sumWith(&a, &sum_a);
  other.join();
  EXPECT_EQ(sum_a, 2000u * 4950u);
  EXPECT_EQ(sum_b, 2000u * 4950u);
}

}  // namespace
}  // namespace panmap
