#include "ontime/allocators/branch_and_bound.hpp"

#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

#include "allocators/detail/anytime_budget.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/util/random.hpp"

namespace ontime {

BranchAndBoundAllocator::BranchAndBoundAllocator(const Mdp& mdp, BranchAndBoundOptions options)
    : mdp_(&mdp), options_(std::move(options)), search_(mdp, options_.max_states) {}

namespace {

// The first `share` of a budget: its iterations and seconds scaled (at least one iteration), its
// stop condition kept.
DecisionBudget share_of(const DecisionBudget& budget, double share) {
  const auto iterations = budget.max_iterations();
  const auto seconds = budget.max_seconds();
  const auto scaled_iterations = [&] {
    return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(share * static_cast<double>(*iterations)));
  };
  DecisionBudget scaled;
  if (iterations && seconds) {
    scaled = DecisionBudget::either(scaled_iterations(), share * *seconds);
  } else if (iterations) {
    scaled = DecisionBudget::iterations(scaled_iterations());
  } else if (seconds) {
    scaled = DecisionBudget::seconds(share * *seconds);
  }
  if (budget.stop_condition()) scaled.or_until(budget.stop_condition());
  return scaled;
}

// The counters both forms report (branch_and_bound_kind's declarations).
void add_search_counters(Statistics& statistics, std::uint64_t searches, std::uint64_t work, std::uint64_t trial_work,
                         std::uint64_t exact, double gap_sum, double max_gap) {
  statistics.add(kSearchesCounter, static_cast<double>(searches));
  statistics.add(kIterationsCounter, static_cast<double>(work));
  statistics.add("trial_work", static_cast<double>(trial_work));
  statistics.add("exact_decisions", static_cast<double>(exact));
  statistics.add("gap_sum", gap_sum);
  statistics.add("max_gap", max_gap, Statistics::Merge::max);
}

}  // namespace

void BranchAndBoundAllocator::begin_episode(std::uint64_t seed) {
  episode_seed_ = seed;
  restarts_ = 0;
  search_.clear(seed);
  last_gap_ = 0.0;
}

int BranchAndBoundAllocator::choose(const State& state) { return choose(state, options_.budget); }

int BranchAndBoundAllocator::choose(const State& state, const DecisionBudget& budget) {
  last_gap_ = 0.0;
  const ChoiceList choices = mdp_->useful_choices(state);
  if (choices.empty()) return mdp_->first_with_work_left(state);
  if (choices.size() == 1) return choices[0];
  // A table at its cap starts again (the cap counts the states of the episode so far), its trials
  // drawing from a stream of the episode's seed.
  if (search_.size() >= options_.max_states) search_.clear(stream_seed(episode_seed_, ++restarts_));
  const DecisionBudget& decision = budget.is_set() ? budget : options_.budget;
  const BudgetMonitor monitor(decision);
  std::uint64_t work = 0;
  std::uint64_t trial_work = 0;
  const bool open_ended = !decision.max_iterations() && !decision.max_seconds();
  const SearchSolution found = open_ended && options_.trial_share > 0.0 && options_.trial_share < 1.0
                                   ? in_rounds(state, monitor, work, trial_work)
                                   : in_two_parts(state, decision, monitor, work, trial_work);
  ++counters_.searches;
  counters_.work += work;
  counters_.trial_work += trial_work;
  if (found.exact) ++counters_.exact;
  last_gap_ = std::max(0.0, found.upper - found.lower);
  counters_.gap_sum += last_gap_;
  counters_.max_gap = std::max(counters_.max_gap, last_gap_);
  return found.first_choice >= 0 ? found.first_choice : choices[0];
}

SearchSolution BranchAndBoundAllocator::in_two_parts(const State& state, const DecisionBudget& decision,
                                                     const BudgetMonitor& monitor, std::uint64_t& work,
                                                     std::uint64_t& trial_work) {
  SearchSolution found;
  if (options_.trial_share > 0.0) {
    const BudgetMonitor share(share_of(decision, options_.trial_share));
    found = search_.trials(state, [&](std::uint64_t done) {
      work = done;
      return share.exhausted(done) || monitor.exhausted(done);
    });
    if (found.exact) {
      trial_work = work;
      return found;
    }
  }
  trial_work = work;
  if (trial_work == 0 || !monitor.exhausted(trial_work)) {
    found = search_.search(state, [&](std::uint64_t done) {
      work = trial_work + done;
      return monitor.exhausted(work);
    });
  }
  return found;
}

SearchSolution BranchAndBoundAllocator::in_rounds(const State& state, const BudgetMonitor& monitor, std::uint64_t& work,
                                                  std::uint64_t& trial_work) {
  SearchSolution found;
  for (std::uint64_t round = kFirstRound;; round *= 2) {
    const auto trial_quota =
        std::max<std::uint64_t>(1, static_cast<std::uint64_t>(options_.trial_share * static_cast<double>(round)));
    const auto search_quota = std::max<std::uint64_t>(1, round - std::min(round, trial_quota));
    bool stopped = false;
    bool quota_spent = false;
    const std::uint64_t before_trials = work;
    found = search_.trials(state, [&](std::uint64_t done) {
      work = before_trials + done;
      stopped = monitor.exhausted(work);
      return stopped || done >= trial_quota;
    });
    trial_work += work - before_trials;
    if (found.exact || stopped) return found;
    const std::uint64_t before_search = work;
    found = search_.search(state, [&](std::uint64_t done) {
      work = before_search + done;
      stopped = monitor.exhausted(work);
      quota_spent = done >= search_quota;
      return stopped || quota_spent;
    });
    // Ended by neither the budget nor its quota: by the state cap, which the next round would hit
    // at once.
    if (found.exact || stopped || !quota_spent) return found;
  }
}

void BranchAndBoundAllocator::collect_statistics(Statistics& statistics) const {
  add_search_counters(statistics, counters_.searches, counters_.work, counters_.trial_work, counters_.exact,
                      counters_.gap_sum, counters_.max_gap);
}

ConcurrentBranchAndBoundAllocator::ConcurrentBranchAndBoundAllocator(const ConcurrentMdp& mdp,
                                                                     BranchAndBoundOptions options)
    : mdp_(&mdp), options_(std::move(options)), search_(mdp, options_.max_states) {}

void ConcurrentBranchAndBoundAllocator::begin_episode(std::uint64_t seed) {
  episode_seed_ = seed;
  restarts_ = 0;
  search_.clear(seed);
  last_gap_ = 0.0;
}

ConcurrentMdp::Move ConcurrentBranchAndBoundAllocator::choose(const ConcurrentState& state) {
  last_gap_ = 0.0;
  if (mdp_->certain_success(state)) return mdp_->run_complete_plan(state);
  const std::vector<ConcurrentMdp::Move> moves = mdp_->useful_moves(state);
  if (moves.empty()) return {};
  if (moves.size() == 1) return moves[0];
  // Records at their cap start again (the cap counts the records of the episode so far), the
  // trials drawing from a stream of the episode's seed.
  if (search_.size() >= options_.max_states) search_.clear(stream_seed(episode_seed_, ++restarts_));
  const BudgetMonitor monitor(options_.budget);
  const ConcurrentSearchResult found =
      search_.search(state, [&](std::uint64_t work) { return monitor.exhausted(work); });
  ++counters_.searches;
  counters_.work += found.work;
  if (found.exact) ++counters_.exact;
  last_gap_ = found.exact ? 0.0 : std::max(0.0, found.upper - found.lower);
  counters_.gap_sum += last_gap_;
  counters_.max_gap = std::max(counters_.max_gap, last_gap_);
  return found.lower >= 0.0 ? found.move : moves[0];
}

void ConcurrentBranchAndBoundAllocator::collect_statistics(Statistics& statistics) const {
  // Its search is all trials.
  add_search_counters(statistics, counters_.searches, counters_.work, counters_.work, counters_.exact,
                      counters_.gap_sum, counters_.max_gap);
}

AllocatorKind branch_and_bound_kind() {
  return {
      .name = "branch-and-bound",
      .summary =
          "branch and bound from the current state within a budget per decision: optimal where it ends, else "
          "the best certified lower end and its gap",
      .capabilities = {Capability::anytime, Capability::certified, Capability::chains},
      .parameters = {Parameter::integer("iterations", 10'000, 1, Parameter::kNoLimit,
                                        "work per decision: states expanded by a trial or an upper test, or "
                                        "solved (no limit when only time-budget is given)"),
                     Parameter::real("time-budget", 0, 0, Parameter::kNoLimit,
                                     "seconds per decision, 0: none (with iterations, whichever ends first)"),
                     Parameter::real("trials", 0.5, 0, 1,
                                     "share of each decision's budget spent first on trials of bounded RTDP, "
                                     "which raise the lower ends of all the choices that may be best"),
                     Parameter::integer("max-states", 10'000'000, 1, Parameter::kNoLimit,
                                        "states the search may hold in an episode (past it, it starts again)")},
      .make = [](const Mdp& mdp, const ParameterReader& parameters) -> AllocatorFactory {
        BranchAndBoundOptions options;
        options.budget = detail::default_budget(parameters);
        options.max_states = parameters.integer("max-states");
        options.trial_share = parameters.real("trials");
        BranchAndBoundAllocator probe(mdp, options);  // the bounds' tables fit: checked before any episode
        return [model = &mdp, options] { return std::make_unique<BranchAndBoundAllocator>(*model, options); };
      },
      .needs = {.decision_budget = detail::given_budget,
                .memory = {.parameter = "max-states",
                           .bytes =
                               [](const Problem& problem, const ParameterReader& parameters) {
                                 return OptimalSolver::max_bytes(problem, parameters.integer("max-states"));
                               },
                           .per_allocator = true},
                .counters = {{kSearchesCounter, "decisions that ran a search"},
                             {kIterationsCounter,
                              "work of the decisions: states expanded by trials or upper tests, or solved"},
                             {"trial_work", "the part of that work spent on trials"},
                             {"exact_decisions", "decisions whose search finished (the optimal choice)"},
                             {"gap_sum", "certified gaps, summed over the decisions"},
                             {"max_gap", "the largest certified gap of a decision"}}},
      .commit_rule =
          "the search's: starts an action when starting has the best certified lower end (the "
          "optimum's where the search closes), weighing that a later give-up blaming a started motion blocks its "
          "action",
      .make_concurrent = [](const ConcurrentMdp& mdp, const ParameterReader& parameters) -> ConcurrentAllocatorFactory {
        if (parameters.given("trials")) {
          throw UsageError(
              "parameter 'trials': acting while planning (SPEC §10) the search is all trials; it takes no share");
        }
        BranchAndBoundOptions options;
        options.budget = detail::default_budget(parameters);
        options.max_states = parameters.integer("max-states");
        return [model = &mdp, options] { return std::make_unique<ConcurrentBranchAndBoundAllocator>(*model, options); };
      }};
}

}  // namespace ontime
