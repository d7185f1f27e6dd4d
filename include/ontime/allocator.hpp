#pragma once
// The interface every effort allocator implements: one decision per step of effort.
//
// An allocator is asked, before every step, which skeleton to refine next. It sees the MDP
// state of SPEC §2 and nothing else: the planning and execution times an episode will reveal
// are hidden from it. Allocators may keep state between decisions (a fixed choice, a search
// tree); `begin_episode` resets it and `observe` reports each transition. An allocator that
// draws random numbers draws them from the seed `begin_episode` hands it, so that an episode's
// decisions do not depend on which thread ran the episodes before it.
//
// One allocator object serves one episode at a time and is not thread-safe; use an
// AllocatorFactory to give each thread its own. Heavy precomputation is shared by the
// objects a factory makes.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/state.hpp"

namespace ontime {

// What a searching allocator (mcts) did, accumulated over its decisions.
struct SearchStatistics {
  std::uint64_t searches = 0;        // decisions that ran a search
  std::uint64_t iterations = 0;      // search iterations over all searches
  std::size_t peak_tree_nodes = 0;   // largest tree held (decision + chance nodes)
  std::size_t peak_tree_bytes = 0;   // its memory, capacity included
  std::uint64_t memory_stops = 0;    // searches ended early by the memory cap

  void merge(const SearchStatistics& other) noexcept {
    searches += other.searches;
    iterations += other.iterations;
    peak_tree_nodes = peak_tree_nodes > other.peak_tree_nodes ? peak_tree_nodes : other.peak_tree_nodes;
    peak_tree_bytes = peak_tree_bytes > other.peak_tree_bytes ? peak_tree_bytes : other.peak_tree_bytes;
    memory_stops += other.memory_stops;
  }
};

class Allocator {
 public:
  virtual ~Allocator() = default;

  virtual std::string_view name() const noexcept = 0;

  // Starts a new episode from the start state; `seed` seeds any randomness of the episode.
  virtual void begin_episode(std::uint64_t seed) { (void)seed; }

  // The skeleton (0-based) to spend the next step on. Ties go to the lowest index.
  virtual int choose(const State& state) = 0;

  // The transition that followed the last `choose`.
  virtual void observe(const State& before, int choice, const State& after, Status status) {
    (void)before, (void)choice, (void)after, (void)status;
  }

  // True when `choose` is a function of the state alone (no history, no randomness), so
  // that the exact success probability can be computed over the reachable states (SPEC §4).
  virtual bool is_stationary() const noexcept { return true; }

  // Statistics of a searching allocator, or nullptr.
  virtual const SearchStatistics* search_statistics() const noexcept { return nullptr; }
};

using AllocatorFactory = std::function<std::unique_ptr<Allocator>()>;

}  // namespace ontime
