#pragma once
// `branch-and-bound`: the anytime allocator of the branch-and-bound search
// (solve/search_solver.hpp), with a certified bound on the loss of every decision.
//
// Before every step it runs the search from the current state within its budget (work units: a
// state solved, or expanded by an upper test; or seconds; or the caller's stop condition),
// keeping what it solved and refined for the rest of the episode, so that later decisions start
// from it. Where the search finishes, the choice is the optimal one (the memoised solver's).
// Cut short, it takes the choice with the best certified lower end and reports the gap: the
// upper end of V*(state) minus that lower end, never below the choice's true loss
// V*(state) - Q*(state, choice).
//
// Deterministic: the search is cleared at the start of every episode, so an episode's decisions
// depend on its own history only, and with a work budget on no property of the machine. Not
// stationary (a decision depends on what the episode solved before it). Cost per decision: its
// budget; memory: the search's table, cleared when it holds `max-states` states.

#include <cstdint>
#include <string_view>

#include "ontime/allocators/allocator.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/solve/search_solver.hpp"

namespace ontime {

struct BranchAndBoundOptions {
  DecisionBudget budget = DecisionBudget::iterations(10'000);
  std::uint64_t max_states = 10'000'000;
};

class BranchAndBoundAllocator final : public Allocator {
 public:
  // Builds ValueBounds' tables (ResourceLimitError past their cap).
  BranchAndBoundAllocator(const Mdp& mdp, BranchAndBoundOptions options);

  std::string_view name() const noexcept override { return "branch-and-bound"; }
  void begin_episode(std::uint64_t seed) override;
  int choose(const State& state) override;
  int choose(const State& state, const DecisionBudget& budget) override;
  bool is_stationary() const noexcept override { return false; }
  void collect_statistics(Statistics& statistics) const override;

  // The certified gap of the last decision (0 when its search finished, or when only one choice
  // was useful).
  double last_gap() const noexcept { return last_gap_; }

 private:
  const Mdp* mdp_;
  BranchAndBoundOptions options_;
  BranchAndBoundSearch search_;
  double last_gap_ = 0.0;
  struct Counters {
    std::uint64_t searches = 0, work = 0, exact = 0;
    double gap_sum = 0.0, max_gap = 0.0;
  } counters_;
};

}  // namespace ontime
