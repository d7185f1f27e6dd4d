#include "ontime/allocators/optimal.hpp"

#include <variant>
#include <vector>

#include "../expectimax.hpp"
#include "ontime/allocator_registry.hpp"

namespace ontime {
namespace {

// Choices and state keys of the optimal solver; Words > 0 packs keys into that many 64-bit
// words (detail::pack), 0 keys by the whole state (detail::compact).
template <std::size_t Words>
class OptimalPolicy {
 public:
  explicit OptimalPolicy(const Mdp& mdp) : mdp_(&mdp) {}

  void choices(const detail::CompactState& state, std::vector<int>& out) const {
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

using Search = std::variant<detail::Expectimax<OptimalPolicy<2>>, detail::Expectimax<OptimalPolicy<4>>,
                            detail::Expectimax<OptimalPolicy<0>>>;

}  // namespace

struct OptimalSolver::Impl {
  Impl(const Mdp& mdp, std::size_t max_states) : search(make(mdp, max_states)) {}

  static Search make(const Mdp& mdp, std::size_t max_states) {
    const auto build = [&]<std::size_t Words>() -> Search {
      return detail::Expectimax<OptimalPolicy<Words>>(mdp, OptimalPolicy<Words>(mdp), max_states,
                                                      OptimalSolver::kTieTolerance, "optimal");
    };
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

std::size_t OptimalSolver::states() const noexcept {
  return std::visit([](const auto& search) { return search.memo().size(); }, impl_->search);
}

OptimalAllocator::OptimalAllocator(const Mdp& mdp, std::size_t max_states) : mdp_(&mdp) {
  auto solver = std::make_shared<OptimalSolver>(mdp, max_states);
  solver->solve(mdp.start());
  solved_ = std::move(solver);
}

OptimalAllocator::OptimalAllocator(const Mdp& mdp, std::shared_ptr<const OptimalSolver> solved)
    : mdp_(&mdp), solved_(std::move(solved)) {}

int OptimalAllocator::choose(const State& state) {
  if (const auto choice = solved_->best_choice(state)) return *choice;
  if (private_) {
    if (const auto choice = private_->best_choice(state)) return *choice;
  } else {
    private_ = std::make_unique<OptimalSolver>(*mdp_, solved_->max_states());
  }
  private_->solve(state);
  // No choice at all means no skeleton can succeed; any choice is as good as another.
  return private_->best_choice(state).value_or(0);
}

std::size_t max_states_of(const ParameterValues& values) {
  const AllocatorKind& optimal = allocator_registry().find("optimal");
  for (const Parameter& parameter : optimal.parameters) {
    if (const std::string* value = values.find(parameter.name)) parameter.check(*value);
  }
  return ParameterReader(optimal, values).integer("max-states");
}

AllocatorKind optimal_kind() {
  return {.name = "optimal",
          .summary = "exact expectimax over the reachable MDP: the highest success probability any allocator can reach",
          .capabilities = {Capability::stationary, Capability::optimal},
          .parameters = {Parameter::integer("max-states", OptimalSolver::kDefaultMaxStates, 1, Parameter::kNoLimit,
                                            "cap on the states the exact solver and the exact evaluation may hold")},
          .make = [](const Mdp& mdp, const ParameterReader& parameters) -> AllocatorFactory {
            auto solver = std::make_shared<OptimalSolver>(mdp, parameters.integer("max-states"));
            solver->solve(mdp.start());
            std::shared_ptr<const OptimalSolver> solved = std::move(solver);
            return [model = &mdp, solved] { return std::make_unique<OptimalAllocator>(*model, solved); };
          }};
}

}  // namespace ontime
