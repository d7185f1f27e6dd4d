#pragma once
// The library's thread pool: a fixed set of threads working through the indices 0..count-1 in
// blocks. Which thread takes which block varies from run to run, so callers store results by
// index or merge per-thread results that do not depend on the order (sums, maxima), and draw
// randomness from per-index seeds; then the results do not depend on the thread count.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace ontime {

// The number of threads for_each_block uses for `count` indices: `threads` (0: one per hardware
// thread), at most one per index, at least one.
inline unsigned worker_count(std::uint64_t count, unsigned threads) noexcept {
  const unsigned wanted = threads != 0 ? threads : std::thread::hardware_concurrency();
  return static_cast<unsigned>(std::max<std::uint64_t>(1, std::min<std::uint64_t>(wanted, count)));
}

// Runs `make_worker(thread)` once on each of the worker_count(count, threads) threads (thread =
// 0, 1, ...; the calling thread is thread 0), then hands out the indices in blocks of `block`
// consecutive ones: that thread's `worker(begin, end)` for each block it takes. Blocks larger
// than one keep the hand-out cheap when one index is little work. The first exception thrown
// stops the hand-out and is rethrown once every thread is done.
template <class MakeWorker>
void for_each_block(std::uint64_t count, unsigned threads, std::uint64_t block, const MakeWorker& make_worker) {
  block = std::max<std::uint64_t>(block, 1);
  const unsigned workers = worker_count(count, threads);
  std::atomic<std::uint64_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&](unsigned thread) {
    try {
      auto worker = make_worker(thread);
      for (std::uint64_t begin = next.fetch_add(block); begin < count; begin = next.fetch_add(block)) {
        worker(begin, std::min(count, begin + block));
      }
    } catch (...) {
      const std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = count;
    }
  };
  {
    std::vector<std::jthread> pool;
    pool.reserve(workers - 1);
    for (unsigned thread = 1; thread < workers; ++thread) pool.emplace_back(work, thread);
    work(0);
  }
  if (failure) std::rethrow_exception(failure);
}

}  // namespace ontime
