#include "ontime/allocators/branch_and_bound.hpp"

#include <algorithm>
#include <memory>
#include <utility>

#include "allocators/detail/anytime_budget.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/solve/optimal_solver.hpp"

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

}  // namespace

void BranchAndBoundAllocator::begin_episode(std::uint64_t seed) {
  search_.clear(seed);
  last_gap_ = 0.0;
}

int BranchAndBoundAllocator::choose(const State& state) { return choose(state, options_.budget); }

int BranchAndBoundAllocator::choose(const State& state, const DecisionBudget& budget) {
  last_gap_ = 0.0;
  const ChoiceList choices = mdp_->useful_choices(state);
  if (choices.empty()) return mdp_->first_with_work_left(state);
  if (choices.size() == 1) return choices[0];
  // A table at its cap starts again (the cap counts the states of the episode so far).
  if (search_.size() >= options_.max_states) search_.clear();
  const DecisionBudget& decision = budget.is_set() ? budget : options_.budget;
  const BudgetMonitor monitor(decision);
  std::uint64_t work = 0;
  SearchSolution found;
  bool settled = false;  // the trials found the state solved
  if (options_.trial_share > 0.0) {
    const BudgetMonitor share(share_of(decision, options_.trial_share));
    found = search_.trials(state, [&](std::uint64_t done) {
      work = done;
      return share.exhausted(done) || monitor.exhausted(done);
    });
    settled = found.exact;
  }
  const std::uint64_t trial_work = work;
  if (!settled && (trial_work == 0 || !monitor.exhausted(trial_work))) {
    found = search_.search(state, [&](std::uint64_t done) {
      work = trial_work + done;
      return monitor.exhausted(work);
    });
  }
  ++counters_.searches;
  counters_.work += work;
  if (found.exact) ++counters_.exact;
  last_gap_ = std::max(0.0, found.upper - found.lower);
  counters_.gap_sum += last_gap_;
  counters_.max_gap = std::max(counters_.max_gap, last_gap_);
  return found.first_choice >= 0 ? found.first_choice : choices[0];
}

void BranchAndBoundAllocator::collect_statistics(Statistics& statistics) const {
  statistics.add(kSearchesCounter, static_cast<double>(counters_.searches));
  statistics.add(kIterationsCounter, static_cast<double>(counters_.work));
  statistics.add("exact_decisions", static_cast<double>(counters_.exact));
  statistics.add("gap_sum", counters_.gap_sum);
  statistics.add("max_gap", counters_.max_gap, Statistics::Merge::max);
}

AllocatorKind branch_and_bound_kind() {
  return {.name = "branch-and-bound",
          .summary =
              "branch and bound from the current state within a budget per decision: optimal where it ends, else "
              "the best certified lower end and its gap",
          .capabilities = {Capability::anytime, Capability::certified},
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
                                 {"exact_decisions", "decisions whose search finished (the optimal choice)"},
                                 {"gap_sum", "certified gaps, summed over the decisions"},
                                 {"max_gap", "the largest certified gap of a decision"}}}};
}

}  // namespace ontime
