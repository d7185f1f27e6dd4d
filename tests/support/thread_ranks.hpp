#pragma once
// Ranks played by threads of one process, for tests of work split over ranks without an MPI
// launcher: run_on_ranks(n, body) runs body(ranks) on n threads, each with its own rank of one
// group, and all_gather meets them like MPI_Allgather would. (Every rank must reach each
// all_gather, as with MPI: a body that throws on one rank only would leave the others waiting.)

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "ontime/util/ranks.hpp"

namespace ontime::testing {

class ThreadRankGroup {
 public:
  explicit ThreadRankGroup(int size) : size_(size), slots_(static_cast<std::size_t>(size)) {}
  int size() const noexcept { return size_; }

  std::vector<std::string> all_gather(int rank, std::string_view bytes) {
    std::unique_lock lock(mutex_);
    slots_[static_cast<std::size_t>(rank)] = std::string(bytes);
    if (++arrived_ == size_) {
      gathered_ = slots_;
      arrived_ = 0;
      ++generation_;
      changed_.notify_all();
      return gathered_;
    }
    const std::uint64_t generation = generation_;
    changed_.wait(lock, [&] { return generation_ != generation; });
    return gathered_;  // the next exchange cannot end before this rank has joined it
  }

 private:
  int size_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::string> slots_, gathered_;
  int arrived_ = 0;
  std::uint64_t generation_ = 0;
};

class ThreadRank final : public Ranks {
 public:
  ThreadRank(ThreadRankGroup& group, int rank) : group_(&group), rank_(rank) {}
  int rank() const noexcept override { return rank_; }
  int size() const noexcept override { return group_->size(); }
  std::vector<std::string> all_gather(std::string_view bytes) const override {
    return group_->all_gather(rank_, bytes);
  }

 private:
  ThreadRankGroup* group_;
  int rank_;
};

// Runs body(ranks) on `size` threads, one per rank; each body's exception is rethrown (the first).
inline void run_on_ranks(int size, const std::function<void(const Ranks&)>& body) {
  ThreadRankGroup group(size);
  std::vector<std::exception_ptr> failures(static_cast<std::size_t>(size));
  {
    std::vector<std::jthread> threads;
    for (int rank = 0; rank < size; ++rank) {
      threads.emplace_back([&, rank] {
        try {
          const ThreadRank ranks(group, rank);
          body(ranks);
        } catch (...) {
          failures[static_cast<std::size_t>(rank)] = std::current_exception();
        }
      });
    }
  }
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
}

}  // namespace ontime::testing
