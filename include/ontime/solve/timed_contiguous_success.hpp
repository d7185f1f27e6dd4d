#pragma once
// Eq. (1) with exogenous chains or expiry (SPEC §9): the expected reward of refining one
// skeleton alone from a state, with the chains observed in that state and modelled from there.
//
// Eq. (1) is a formula over static distributions: a chain-dependent execution, a door that
// locks or a queue that grows have no place in it. What it computes without chains is the value
// of one policy, "spend every remaining step on skeleton k" (aggregation `self`), and that policy
// has an exact value with chains too:
//   V_k(s) = sum_o P(o | s, k) ([o succeeds] R(o) + [o running] V_k(o)),
// the sum over the outcomes of SPEC §9 (refinement, then one step of the chains), R the plan's
// expected reward over the chains' paths while it executes. A skeleton that shares k's actions
// and completes on the way counts, as in the MDP. This is the rule `dp` and `dp-rerun` use for
// such an instance: they read the chains now and assume their model from now on, but never
// wait for them (a policy that refines k alone does not idle).
//
// Guarantees: V_k(s) is exact (the memoised expectimax of the exact solver with the one choice
// k); tested against an independent recursion on random instances.
// Cost: each V_k is memoised over the states that refining k alone reaches (at most
// D x positions x D x |ET values| x joint chain states), shared by every later query of the same
// object; a query after warm-up is one hash look-up. Not thread-safe: one object per allocator.

#include <cstddef>
#include <memory>

#include "ontime/mdp/mdp.hpp"

namespace ontime {

class TimedContiguousSuccess {
 public:
  // The Mdp must outlive the object. Throws UsageError for an instance that is not timed (no
  // chain and no expiry: Eq. (1)'s tables serve it) or that the exact solvers' keys cannot hold.
  explicit TimedContiguousSuccess(const Mdp& mdp, std::size_t max_states = kDefaultMaxStates);
  ~TimedContiguousSuccess();
  TimedContiguousSuccess(const TimedContiguousSuccess&) = delete;
  TimedContiguousSuccess& operator=(const TimedContiguousSuccess&) = delete;
  TimedContiguousSuccess(TimedContiguousSuccess&&) noexcept;
  TimedContiguousSuccess& operator=(TimedContiguousSuccess&&) noexcept;

  // V_k(state). Throws ResourceLimitError once skeleton k's memo holds `max_states` states.
  double expected_reward(const State& state, int k);

  // States memoised so far, over every skeleton.
  std::size_t memoised() const noexcept;

  // 10 million states of about 130 bytes per skeleton: past that a user needs another allocator.
  static constexpr std::size_t kDefaultMaxStates = 10'000'000;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ontime
