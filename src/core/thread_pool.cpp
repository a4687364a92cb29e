#include "panmap/core/thread_pool.h"

#include <algorithm>
#include <atomic>
#include <chrono>

namespace panmap {

ThreadPool::ThreadPool(int num_threads) {
  for (int i = 1; i < std::max(1, num_threads); ++i) {
    workers_.emplace_back([this, i] { workerLoop(i); });
  }
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  start_cv_.notify_all();
  for (std::thread& t : workers_) t.join();
}

namespace {

// How long a thread polls for work, or for the others to finish, before it sleeps.
constexpr auto kSpin = std::chrono::microseconds(50);

// Polls done() until it holds or kSpin has passed; returns done().
template <typename Done>
bool spinUntil(const Done& done) {
  const auto until = std::chrono::steady_clock::now() + kSpin;
  while (!done()) {
    for (int i = 0; i < 64; ++i) {
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();
#endif
    }
    if (std::chrono::steady_clock::now() > until) return done();
  }
  return true;
}

void runSlice(const std::function<void(size_t, size_t, int)>& fn, size_t n, int threads, int t) {
  const size_t begin = n * static_cast<size_t>(t) / static_cast<size_t>(threads);
  const size_t end = n * static_cast<size_t>(t + 1) / static_cast<size_t>(threads);
  if (begin < end) fn(begin, end, t);
}

}  // namespace

void ThreadPool::parallelFor(size_t n, const std::function<void(size_t, size_t, int)>& fn) {
  if (workers_.empty() || n < 2) {
    if (n > 0) fn(0, n, 0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &fn;
    job_size_ = n;
    pending_ = static_cast<int>(workers_.size());
    ++generation_;
  }
  start_cv_.notify_all();
  runSlice(fn, n, size(), 0);
  spinUntil([this] { return pending_.load(std::memory_order_acquire) == 0; });
  std::unique_lock<std::mutex> lock(mutex_);
  done_cv_.wait(lock, [this] { return pending_ == 0; });
  job_ = nullptr;
}

void ThreadPool::parallelForDynamic(size_t n, size_t grain,
                                    const std::function<void(size_t, size_t, int)>& fn) {
  grain = std::max<size_t>(grain, 1);
  if (workers_.empty() || n <= grain) {
    if (n > 0) fn(0, n, 0);
    return;
  }
  std::atomic<size_t> next{0};
  parallelFor(static_cast<size_t>(size()), [&](size_t, size_t, int thread) {
    for (size_t begin = next.fetch_add(grain); begin < n; begin = next.fetch_add(grain)) {
      fn(begin, std::min(n, begin + grain), thread);
    }
  });
}

void ThreadPool::workerLoop(int index) {
  uint64_t seen = 0;
  while (true) {
    const std::function<void(size_t, size_t, int)>* job;
    size_t n;
    spinUntil([&] { return generation_.load(std::memory_order_acquire) != seen; });
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_cv_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      job = job_;
      n = job_size_;
    }
    runSlice(*job, n, size(), index);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (--pending_ == 0) done_cv_.notify_one();
    }
  }
}

}  // namespace panmap
