#pragma once
// Internal: a fixed set of threads working through indices 0..count-1. Which thread takes which
// index varies from run to run, so callers store results by index and draw randomness from
// per-index seeds; then the results do not depend on the thread count.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace ontime::domains::detail {

// `make_worker()` runs once per thread and returns that thread's `worker(index)`. The first
// exception thrown stops the handing out of indices and is rethrown once every thread is done.
template <class MakeWorker>
void for_each_index(std::uint64_t count, unsigned threads, const MakeWorker& make_worker) {
  const unsigned workers = std::max(1u, threads != 0 ? threads : std::thread::hardware_concurrency());
  std::atomic<std::uint64_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&] {
    try {
      auto worker = make_worker();
      for (std::uint64_t index = next++; index < count; index = next++) worker(index);
    } catch (...) {
      const std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = count;
    }
  };
  std::vector<std::thread> pool;
  for (unsigned i = 1; i < workers; ++i) pool.emplace_back(work);
  work();
  for (std::thread& thread : pool) thread.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace ontime::domains::detail
