#include "ontime/solve/optimal_solver.hpp"

#include <variant>
#include <vector>

#include "ontime/util/error.hpp"
#include "solve/expectimax.hpp"

namespace ontime {
namespace {

using Search =
    std::variant<detail::Expectimax<detail::OptimalPolicy<2>>, detail::Expectimax<detail::OptimalPolicy<4>>,
                 detail::Expectimax<detail::OptimalPolicy<0>>, detail::Expectimax<detail::OptimalBacktrackPolicy>,
                 detail::Expectimax<detail::OptimalTimedPolicy>>;

}  // namespace

struct OptimalSolver::Impl {
  Impl(const Mdp& mdp, std::size_t max_states) : search(make(mdp, max_states)) {}

  static Search make(const Mdp& mdp, std::size_t max_states) {
    const auto build = [&]<std::size_t Words>() -> Search {
      return detail::Expectimax<detail::OptimalPolicy<Words>>(mdp, detail::OptimalPolicy<Words>(mdp), max_states,
                                                              OptimalSolver::kTieTolerance, "optimal");
    };
    if (mdp.is_timed()) {
      return detail::Expectimax<detail::OptimalTimedPolicy>(mdp, detail::OptimalTimedPolicy(mdp), max_states,
                                                            OptimalSolver::kTieTolerance, "optimal");
    }
    if (mdp.has_backtracking()) {
      return detail::Expectimax<detail::OptimalBacktrackPolicy>(mdp, detail::OptimalBacktrackPolicy(mdp), max_states,
                                                                OptimalSolver::kTieTolerance, "optimal");
    }
    switch (detail::packed_words(mdp)) {
      case 2:
        return build.template operator()<2>();
      case 4:
        return build.template operator()<4>();
      default:
        return build.template operator()<0>();
    }
  }

  Search search;
};

OptimalSolver::OptimalSolver(const Mdp& mdp, std::size_t max_states)
    : mdp_(&mdp), max_states_(max_states), impl_(std::make_unique<Impl>(mdp, max_states)) {}
OptimalSolver::~OptimalSolver() = default;
void OptimalSolver::set_stop(std::function<bool()> stop) {
  std::visit([&](auto& search) { search.set_stop(std::move(stop)); }, impl_->search);
}
OptimalSolver::OptimalSolver(OptimalSolver&&) noexcept = default;
OptimalSolver& OptimalSolver::operator=(OptimalSolver&&) noexcept = default;

double OptimalSolver::solve(const State& state) {
  return std::visit([&state](auto& search) { return search.solve(state).value; }, impl_->search);
}

std::optional<int> OptimalSolver::best_choice(const State& state) const {
  return std::visit(
      [&state](const auto& search) -> std::optional<int> {
        const auto found = search.memo().find(search.key_of(state));
        if (found == search.memo().end() || found->second.choice < 0) return std::nullopt;
        return found->second.choice;
      },
      impl_->search);
}

double OptimalSolver::max_bytes(const Problem& problem, std::size_t max_states) {
  const double slot_bytes = problem.is_timed()           ? 133
                            : problem.has_backtracking() ? 131
                                                         : (problem.skeleton_count() <= 4 && problem.deadline() <= 253
                                                                ? 33
                                                                : (problem.skeleton_count() <= 10 ? 49 : 99));
  return 3.0 * slot_bytes * static_cast<double>(max_states);
}

// (std::visit throws only for a variant left valueless by an exception, which impl_->search, made
// once and never assigned, cannot be.)
// NOLINTNEXTLINE(bugprone-exception-escape)
std::size_t OptimalSolver::states() const noexcept {
  return std::visit([](const auto& search) { return search.memo().size(); }, impl_->search);
}

void check_exact_work(const Problem& problem, std::size_t max_states, const std::string& source,
                      const ParameterSpelling& spelling) {
  if (problem.skeleton_count() > kMaxExactSkeletons) {
    throw InputError(source, "skeletons",
                     std::to_string(problem.skeleton_count()) +
                         " skeletons; exact solving and exact evaluation take at most " +
                         std::to_string(kMaxExactSkeletons) +
                         " (sampled evaluation and the approximate allocators take any number)");
  }
  if (problem.timed_slot_count() > detail::kMaxExactCulpritSlots) {
    throw InputError(source, "actions",
                     std::to_string(problem.timed_slot_count()) +
                         " timed actions (chains or expiry); exact solving and exact evaluation take at most " +
                         std::to_string(detail::kMaxExactCulpritSlots));
  }
  if (problem.culprit_slot_count() > detail::kMaxExactCulpritSlots) {
    throw InputError(source, "actions",
                     std::to_string(problem.culprit_slot_count()) +
                         " actions that backtracking may blame; exact solving and exact evaluation take at most " +
                         std::to_string(detail::kMaxExactCulpritSlots));
  }
  if (detail::recorded_slots(problem) > detail::kMaxExactCulpritSlots) {
    throw InputError(source, "actions",
                     std::to_string(problem.culprit_slot_count()) + " actions that backtracking may blame and " +
                         std::to_string(problem.timed_slot_count()) +
                         " timed actions; exact solving and exact evaluation take at most " +
                         std::to_string(detail::kMaxExactCulpritSlots) + " together");
  }
  check_memory_for(spell_parameter(spelling, "max-states") + " " + std::to_string(max_states),
                   OptimalSolver::max_bytes(problem, max_states));
}

}  // namespace ontime
