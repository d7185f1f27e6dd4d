#pragma once
// `branch-and-bound`: the anytime allocator of the branch-and-bound search
// (solve/search_solver.hpp), with a certified bound on the loss of every decision.
//
// Before every step it spends its budget (work units: a state expanded by a trial or an upper
// test, or solved; or seconds; or the caller's stop condition) from the current state in two
// parts: first `trial_share` of it on trials of bounded RTDP (BranchAndBoundSearch::trials),
// which raise the certified lower ends of every choice that may still be best, then the rest on
// the search, which settles choices by those ends too. A budget of a stop condition alone (the
// caller's clock) has no size to share: trials and search then take turns in rounds of doubling
// work (kFirstRound units, then twice as many, ...), each its share of the round, until the
// search finishes or the condition trips, so that the search runs however soon it trips. It
// keeps what it solved and bounded for the rest of the episode, so that later decisions start
// from it. (The search alone, cut short, has gone deep into the first choice it solves while the
// others keep their static lower ends: on navigation at 10 ms per decision that loses 1.5% of
// the optimum, the trials nothing; docs/experiments.md.) Where the search finishes, the choice
// is the optimal one (the memoised solver's). Cut short, it takes the choice with the best
// certified lower end and reports the gap: the upper end of V*(state) minus that lower end,
// never below the choice's true loss V*(state) - Q*(state, choice). With chains or expiry
// (SPEC §9) the search models them as the exact solver does (its states hold the chains' joint
// state, and it may wait); ValueBounds' lower end is then 0, so a decision cut short leans on
// what its trials and search solved, and its gap is wider than without chains.
//
// Deterministic: the search is cleared at the start of every episode and its trials draw from
// the episode's seed (after a restart at the cap, from a stream of it), so an episode's
// decisions depend on its seed and its own history only, and with a work budget on no property
// of the machine. Not stationary (a decision depends on what the episode solved before it). Cost
// per decision: its budget; memory: the search's table, cleared when it holds `max-states`
// records (see BranchAndBoundSearch::size).

#include <cstdint>
#include <string_view>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/allocators/decision_budget.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/solve/concurrent_search.hpp"
#include "ontime/solve/search_solver.hpp"

namespace ontime {

struct BranchAndBoundOptions {
  DecisionBudget budget = DecisionBudget::iterations(10'000);
  std::uint64_t max_states = 10'000'000;
  // Share of each decision's budget spent first on trials (BranchAndBoundSearch::trials).
  double trial_share = 0.5;
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

  // The first round's work under a budget of a stop condition alone.
  static constexpr std::uint64_t kFirstRound = 256;

 private:
  // Trials on the first trial_share of the budget, then the search on the rest.
  SearchSolution in_two_parts(const State& state, const DecisionBudget& decision, const BudgetMonitor& monitor,
                              std::uint64_t& work, std::uint64_t& trial_work);
  // Trials and search in turns (a budget of a stop condition alone).
  SearchSolution in_rounds(const State& state, const BudgetMonitor& monitor, std::uint64_t& work,
                           std::uint64_t& trial_work);

  const Mdp* mdp_;
  BranchAndBoundOptions options_;
  BranchAndBoundSearch search_;
  double last_gap_ = 0.0;
  std::uint64_t episode_seed_ = 1, restarts_ = 0;
  struct Counters {
    std::uint64_t searches = 0, work = 0, trial_work = 0, exact = 0;
    double gap_sum = 0.0, max_gap = 0.0;
  } counters_;
};

// `branch-and-bound` acting while planning (SPEC §10): before every move it spends its budget
// (work units: a state backed up; or seconds) on ConcurrentSearch from the current state, keeping
// what it bounded for the rest of the episode, and makes the move of the best certified lower end,
// the optimal move where the search closed (the exact solver's value). Its gap, the upper end of
// V*(state) minus that lower end, bounds the move's loss. The search is all trials (there is no
// depth-first part), so `trial_share` is not read. The commit rule is the search's: the robot
// starts an action when starting's certified lower end is the best. Without a search: a complete
// plan without rewards runs at once (certain success), a forced start or the only useful move is
// made. Its trials draw from the episode's seed (the records are cleared at each episode, and at
// `max_states`). Not stationary. Cost per decision: its budget; memory: the search's records.
class ConcurrentBranchAndBoundAllocator final : public ConcurrentAllocator {
 public:
  // The ConcurrentMdp must outlive the allocator.
  ConcurrentBranchAndBoundAllocator(const ConcurrentMdp& mdp, BranchAndBoundOptions options);

  std::string_view name() const noexcept override { return "branch-and-bound"; }
  void begin_episode(std::uint64_t seed) override;
  ConcurrentMdp::Move choose(const ConcurrentState& state) override;
  bool is_stationary() const noexcept override { return false; }
  // searches, iterations (work), exact_decisions, gap_sum (summed); max_gap (largest).
  void collect_statistics(Statistics& statistics) const override;

  // The certified gap of the last decision (0 when its search closed or no search was needed).
  double last_gap() const noexcept { return last_gap_; }

 private:
  const ConcurrentMdp* mdp_;
  BranchAndBoundOptions options_;
  ConcurrentSearch search_;
  double last_gap_ = 0.0;
  std::uint64_t episode_seed_ = 1, restarts_ = 0;
  struct Counters {
    std::uint64_t searches = 0, work = 0, exact = 0;
    double gap_sum = 0.0, max_gap = 0.0;
  } counters_;
};

}  // namespace ontime
