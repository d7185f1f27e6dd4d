#include "ontime/run/evaluation.hpp"

#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "ontime/run/simulator.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/util/error.hpp"
#include "solve/expectimax.hpp"

namespace ontime {
namespace {

// The allocator's own choice is the only choice; states are keyed by their fixed-size copy
// (packed into Words 64-bit words when Words > 0).
template <std::size_t Words, class CompactType = detail::CompactState>
class StationaryPolicy {
 public:
  using Compact = CompactType;
  StationaryPolicy(Allocator& allocator, const Mdp& mdp)
      : allocator_(&allocator), skeleton_count_(mdp.skeleton_count()), scratch_(mdp.start()) {}
  void choices(const Compact& state, std::vector<int>& out) const {
    detail::expanded(state, scratch_);
    const int choice = allocator_->choose(scratch_);
    if (choice < 0 || choice >= skeleton_count_) {
      throw UsageError("allocator '" + std::string(allocator_->name()) + "' chose skeleton " + std::to_string(choice) +
                       ", outside [0, " + std::to_string(skeleton_count_) + ")");
    }
    out.push_back(choice);
  }
  auto key(const Compact& state) const {
    if constexpr (Words > 0) {
      return detail::pack<Words>(state, skeleton_count_);
    } else {
      return state;
    }
  }

 private:
  Allocator* allocator_;
  int skeleton_count_;
  mutable State scratch_;  // the state the allocator is asked about
};

}  // namespace

MonteCarloResult run_monte_carlo(const Mdp& mdp, const AllocatorFactory& factory, const MonteCarloOptions& options) {
  return run_episodes(mdp, hidden_worlds(mdp.problem()), factory, options);
}

ExactEvaluation evaluate_exactly(const Mdp& mdp, Allocator& allocator, std::size_t max_states,
                                 const std::function<bool()>& stop) {
  if (!allocator.is_stationary()) {
    throw UsageError("exact evaluation needs an allocator whose choice depends only on the state; '" +
                     std::string(allocator.name()) + "' does not (use Monte Carlo)");
  }
  allocator.begin_episode(0);
  // The value of the allocator's choices in `model`: `mdp`, or the same states with every
  // reward 1 (its success probability).
  const auto value_in = [&](const Mdp& model) {
    const auto run = [&](auto policy) {
      detail::Expectimax<decltype(policy)> search(model, policy, max_states, 0.0,
                                                  "exact evaluation of " + std::string(allocator.name()));
      search.set_stop(stop);
      const double value = search.solve(model.start()).value;
      return std::make_pair(value, search.memo().size());
    };
    if (model.is_timed()) return run(StationaryPolicy<0, detail::CompactTimedState>(allocator, model));
    if (model.has_backtracking()) return run(StationaryPolicy<0, detail::CompactBacktrackState>(allocator, model));
    switch (detail::packed_words(model)) {
      case 2:
        return run(StationaryPolicy<2>(allocator, model));
      case 4:
        return run(StationaryPolicy<4>(allocator, model));
      default:
        return run(StationaryPolicy<0>(allocator, model));
    }
  };
  ExactEvaluation result;
  std::tie(result.expected_reward, result.states) = value_in(mdp);
  result.success_probability = result.expected_reward;
  if (mdp.problem().has_rewards()) {
    // The same policy (a stationary allocator chooses by the state alone) valued with reward 1.
    const Problem unit = mdp.problem().with_rewards({});
    const Mdp success(unit);
    result.success_probability = value_in(success).first;
  }
  return result;
}

MonteCarloResult run_monte_carlo(const ConcurrentMdp& mdp, const ConcurrentAllocatorFactory& factory,
                                 const MonteCarloOptions& options) {
  return run_concurrent_episodes(mdp, hidden_worlds(mdp.problem()), factory, options);
}

ExactEvaluation evaluate_exactly(const ConcurrentMdp& mdp, ConcurrentAllocator& allocator, std::size_t max_states,
                                 const std::function<bool()>& stop) {
  if (!allocator.is_stationary()) {
    throw UsageError("exact evaluation needs an allocator whose move depends only on the state; '" +
                     std::string(allocator.name()) + "' does not (use Monte Carlo)");
  }
  allocator.begin_episode(0);
  const auto value_in = [&](const ConcurrentMdp& model) {
    ConcurrentSolver solver(
        model, [&](const ConcurrentState& state) { return allocator.choose(state); }, max_states);
    solver.set_stop(stop);
    const double value = solver.solve(model.start());
    return std::make_pair(value, solver.states());
  };
  ExactEvaluation result;
  std::tie(result.expected_reward, result.states) = value_in(mdp);
  result.success_probability = result.expected_reward;
  if (mdp.problem().has_rewards()) {
    // The same moves valued with reward 1: the allocator chooses by the state alone, and the
    // states (which hold no reward) are the same in both models.
    const ConcurrentMdp success(mdp.problem().with_rewards({}));
    result.success_probability = value_in(success).first;
  }
  return result;
}

}  // namespace ontime
