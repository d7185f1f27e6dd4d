#include "ontime/model/chain_averaging.hpp"

#include <algorithm>
#include <cstddef>
#include <string>
#include <utility>

#include "ontime/util/error.hpp"

namespace ontime {

std::vector<double> mean_occupancy(const ExogenousChain& chain, int from, std::int64_t steps) {
  // The first distribution checks the chain, `from` and `steps`; the sum then follows the chain
  // step by step in chain_distribution's order.
  std::vector<double> now = chain_distribution(chain, from, 0);
  if (steps < 0) (void)chain_distribution(chain, from, steps);
  const std::size_t n = now.size();
  std::vector<double> sum = now;
  std::vector<double> next(n);
  for (std::int64_t t = 1; t <= steps; ++t) {
    advance_chain_distribution(chain, now, next);
    now.swap(next);
    for (std::size_t j = 0; j < n; ++j) sum[j] += now[j];
  }
  const auto count = static_cast<double>(steps + 1);
  for (double& value : sum) value /= count;
  return sum;
}

namespace {

// weight * distribution added into masses (grown as needed).
void add_scaled(std::vector<double>& masses, const Distribution& distribution, double weight) {
  const std::span<const double> from = distribution.masses();
  if (masses.size() < from.size()) masses.resize(from.size(), 0.0);
  for (std::size_t t = 0; t < from.size(); ++t) masses[t] += weight * from[t];
}

void add_failure(std::vector<double>& masses, Steps deadline, double weight) {
  const auto too_late = static_cast<std::size_t>(deadline) + 1;
  if (masses.size() <= too_late) masses.resize(too_late + 1, 0.0);
  masses[too_late] += weight;
}

}  // namespace

Problem average_chains(const Problem& problem, std::int64_t horizon) {
  if (horizon < 0) throw UsageError("a horizon >= 0 steps (got " + std::to_string(horizon) + ")");
  if (!problem.has_chains()) return problem;
  const Steps deadline = problem.deadline();
  const std::int64_t steps = horizon == 0 ? std::int64_t{deadline} : horizon;
  std::vector<std::vector<double>> occupancy;
  std::vector<ExogenousChain> averaged_chains;
  for (const ExogenousChain& chain : problem.chains()) {
    occupancy.push_back(mean_occupancy(chain, chain.start, steps));
    averaged_chains.push_back(
        {.name = chain.name, .states = {kAveragedChainState}, .start = 0, .transitions = {{1.0}}});
  }
  std::vector<Action> actions(problem.actions().begin(), problem.actions().end());
  for (int a = 0; a < static_cast<int>(actions.size()); ++a) {
    Action& action = actions[static_cast<std::size_t>(a)];
    const int drawn_from = problem.execution_chain(a);
    const int blocked_by = problem.blocking_chain(a);
    if (drawn_from < 0 && blocked_by < 0) continue;
    // The weight of the blocking chain's states that block the action.
    double blocked = 0;
    if (blocked_by >= 0 && blocked_by != drawn_from) {
      const std::vector<double>& weights = occupancy[static_cast<std::size_t>(blocked_by)];
      for (std::size_t s = 0; s < weights.size(); ++s) {
        if (problem.blocks(a, static_cast<int>(s))) blocked += weights[s];
      }
      // (Weights that sum to 1 may sum a rounding error above it.)
      blocked = std::min(blocked, 1.0);
    }
    std::vector<double> masses;
    if (drawn_from >= 0) {
      const std::vector<double>& weights = occupancy[static_cast<std::size_t>(drawn_from)];
      for (std::size_t s = 0; s < weights.size(); ++s) {
        if (blocked_by == drawn_from && problem.blocks(a, static_cast<int>(s))) {
          add_failure(masses, deadline, weights[s]);
        } else {
          add_scaled(masses, action.execution_by_state[s], weights[s] * (1.0 - blocked));
        }
      }
      if (blocked > 0) add_failure(masses, deadline, blocked);
      action.execution_by_state = {Distribution::from_pmf(std::move(masses))};
      action.execution_chain = problem.chains()[static_cast<std::size_t>(drawn_from)].name;
    } else {
      // Blocked only: the execution stays revealed with the motion, as in the problem, with the
      // blocked weight as an execution that cannot meet the deadline. The action keeps a (vacuous)
      // last start at D so that it stays timed: the same restore layout as the problem's.
      add_scaled(masses, action.execution, 1.0 - blocked);
      add_failure(masses, deadline, blocked);
      action.execution = Distribution::from_pmf(std::move(masses));
      action.start_by = std::min(action.start_by, deadline);
    }
    if (blocked_by >= 0) {
      action.blocking_chain.clear();
      action.blocking_states.clear();
    }
  }
  std::vector<SkeletonReward> rewards(problem.rewards().begin(), problem.rewards().end());
  return {problem.name(),           deadline,
          problem.step_seconds(),   std::move(actions),
          problem.skeleton_lists(), problem.description(),
          std::move(rewards),       std::move(averaged_chains)};
}

}  // namespace ontime
