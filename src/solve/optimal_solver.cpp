#include "ontime/solve/optimal_solver.hpp"

#include <variant>
#include <vector>

#include "ontime/util/error.hpp"
#include "solve/expectimax.hpp"

namespace ontime {
namespace {

// Choices and state keys of the optimal solver; Words > 0 packs keys into that many 64-bit
// words (detail::pack), 0 keys by the whole state (detail::compact).
template <std::size_t Words>
class OptimalPolicy {
 public:
  using Compact = detail::CompactState;
  explicit OptimalPolicy(const Mdp& mdp) : mdp_(&mdp) {}

  void choices(const Compact& state, std::vector<int>& out) const {
    for (const int choice : mdp_->useful_choices(state)) out.push_back(choice);
  }

  // Skeletons in a group that can no longer succeed influence nothing: detail::blank_hopeless
  // blanks their slots so that states differing only there share one memo entry.
  auto key(const detail::CompactState& state) const {
    detail::CompactState key = state;
    detail::blank_hopeless(*mdp_, key);
    if constexpr (Words > 0) {
      return detail::pack<Words>(key, mdp_->skeleton_count());
    } else {
      return key;
    }
  }

 private:
  const Mdp* mdp_;
};

// With backtracking (SPEC §7): states with their restore values, keyed whole. No slot is blanked:
// a step on a group that cannot succeed may still backtrack and restore an action others share.
class OptimalBacktrackPolicy {
 public:
  using Compact = detail::CompactBacktrackState;
  explicit OptimalBacktrackPolicy(const Mdp& mdp) : mdp_(&mdp) {}

  void choices(const Compact& state, std::vector<int>& out) const {
    for (const int choice : mdp_->useful_choices(state)) out.push_back(choice);
  }
  static const Compact& key(const Compact& state) { return state; }

 private:
  const Mdp* mdp_;
};

using Search = std::variant<detail::Expectimax<OptimalPolicy<2>>, detail::Expectimax<OptimalPolicy<4>>,
                            detail::Expectimax<OptimalPolicy<0>>, detail::Expectimax<OptimalBacktrackPolicy>>;

}  // namespace

struct OptimalSolver::Impl {
  Impl(const Mdp& mdp, std::size_t max_states) : search(make(mdp, max_states)) {}

  static Search make(const Mdp& mdp, std::size_t max_states) {
    const auto build = [&]<std::size_t Words>() -> Search {
      return detail::Expectimax<OptimalPolicy<Words>>(mdp, OptimalPolicy<Words>(mdp), max_states,
                                                      OptimalSolver::kTieTolerance, "optimal");
    };
    if (mdp.has_backtracking()) {
      return detail::Expectimax<OptimalBacktrackPolicy>(mdp, OptimalBacktrackPolicy(mdp), max_states,
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
  const double slot_bytes = problem.has_backtracking() ? 131
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
  if (problem.culprit_slot_count() > detail::kMaxExactCulpritSlots) {
    throw InputError(source, "actions",
                     std::to_string(problem.culprit_slot_count()) +
                         " actions that backtracking may blame; exact solving and exact evaluation take at most " +
                         std::to_string(detail::kMaxExactCulpritSlots));
  }
  check_memory_for(spell_parameter(spelling, "max-states") + " " + std::to_string(max_states),
                   OptimalSolver::max_bytes(problem, max_states));
}

}  // namespace ontime
