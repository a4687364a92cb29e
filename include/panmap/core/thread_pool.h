#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace panmap {

/// A fixed set of worker threads that run index ranges in parallel. Threads live as long as
/// the pool, so per-frame work creates no threads.
class ThreadPool {
 public:
  /// @param num_threads total threads working on a range, the caller included (>= 1)
  explicit ThreadPool(int num_threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  /// Threads that share a range, the caller included.
  int size() const { return static_cast<int>(workers_.size()) + 1; }

  /// Calls fn(begin, end, thread) on disjoint chunks covering [0, n) and returns when all are
  /// done. Chunks are static (thread t gets the t-th slice), so results are deterministic
  /// as long as fn's effects depend only on its range.
  void parallelFor(size_t n, const std::function<void(size_t, size_t, int)>& fn);

  /// Like parallelFor, but hands out chunks of `grain` indices to whichever thread is free, so
  /// uneven work per index is balanced. Which thread runs a chunk varies from run to run: use
  /// it only where fn's effect on an index does not depend on the thread (per-thread outputs
  /// must be combined order-independently, e.g. summed counts).
  void parallelForDynamic(size_t n, size_t grain,
                          const std::function<void(size_t, size_t, int)>& fn);

 private:
  void workerLoop(int index);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_cv_;
  std::condition_variable done_cv_;
  const std::function<void(size_t, size_t, int)>* job_ = nullptr;
  size_t job_size_ = 0;
  // Written under mutex_; atomic so that waiting threads can poll them briefly before
  // sleeping on a condition variable (a frame runs a dozen short ranges, and waking a
  // sleeping thread costs tens of microseconds).
  std::atomic<uint64_t> generation_{0};
  std::atomic<int> pending_{0};
  bool stop_ = false;
};

}  // namespace panmap
