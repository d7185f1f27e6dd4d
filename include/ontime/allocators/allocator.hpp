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

#include "ontime/allocators/decision_budget.hpp"
#include "ontime/mdp/state.hpp"
#include "ontime/util/statistics.hpp"

namespace ontime {

class Allocator {
 public:
  virtual ~Allocator() = default;

  // The kind's name, as the registry and the command line spell it: "dp-rerun", "round-robin".
  virtual std::string_view name() const noexcept = 0;

  // Starts a new episode from the start state; `seed` seeds any randomness of the episode.
  virtual void begin_episode(std::uint64_t seed) { (void)seed; }

  // The skeleton (0-based) to spend the next step on. Ties go to the lowest index. An anytime
  // allocator decides within its own default budget (its parameters).
  virtual int choose(const State& state) = 0;

  // The same decision within `budget` (an unset budget: the default one). Only anytime
  // allocators use the budget; the others decide as choose(state), which is already cheap.
  virtual int choose(const State& state, const DecisionBudget& budget) {
    (void)budget;
    return choose(state);
  }

  // The transition that followed the last `choose`.
  virtual void observe(const State& before, int choice, const State& after, Status status) {
    (void)before, (void)choice, (void)after, (void)status;
  }

  // True when `choose` is a function of the state alone (no history, no randomness), so
  // that the exact success probability can be computed over the reachable states (SPEC §4).
  virtual bool is_stationary() const noexcept { return true; }

  // Adds this allocator's counters (work done since it was made) to `statistics`; most
  // allocators have none.
  virtual void collect_statistics(Statistics& statistics) const { (void)statistics; }
};

using AllocatorFactory = std::function<std::unique_ptr<Allocator>()>;

}  // namespace ontime
