#include "ontime/allocators/optimal.hpp"

#include <vector>

#include "../expectimax.hpp"

namespace ontime {
namespace {

// Choices and state keys of the optimal solver.
class OptimalPolicy {
 public:
  explicit OptimalPolicy(const Mdp& mdp) : mdp_(&mdp) {}

  void choices(const State& state, std::vector<int>& out) const {
    for (const int choice : mdp_->useful_choices(state)) out.push_back(choice);
  }

  // Skeletons in a group that can no longer succeed influence nothing: their slots are
  // blanked so that states differing only there share one memo entry.
  State key(const State& state) const {
    State key = state;
    for (int k = 0; k < mdp_->skeleton_count(); ++k) {
      const int action = mdp_->next_action(state, k);
      if (action >= 0 && mdp_->group_can_succeed(state, action)) continue;
      const auto slot = static_cast<std::size_t>(k);
      key.refined[slot] = 0;
      key.spent[slot] = kBlank;
      key.execution[slot] = kBlank;
    }
    return key;
  }

 private:
  static constexpr std::uint16_t kBlank = 0xFFFF;  // above any reachable PT or ET

  const Mdp* mdp_;
};

}  // namespace

struct OptimalSolver::Impl {
  Impl(const Mdp& mdp, std::size_t max_states)
      : search(mdp, OptimalPolicy(mdp), max_states, OptimalSolver::kTieTolerance, "optimal") {}
  detail::Expectimax<OptimalPolicy> search;
};

OptimalSolver::OptimalSolver(const Mdp& mdp, std::size_t max_states)
    : mdp_(&mdp), max_states_(max_states), impl_(std::make_unique<Impl>(mdp, max_states)) {}
OptimalSolver::~OptimalSolver() = default;
OptimalSolver::OptimalSolver(OptimalSolver&&) noexcept = default;
OptimalSolver& OptimalSolver::operator=(OptimalSolver&&) noexcept = default;

double OptimalSolver::solve(const State& state) { return impl_->search.solve(state).value; }

std::optional<int> OptimalSolver::best_choice(const State& state) const {
  const auto& memo = impl_->search.memo();
  const auto found = memo.find(impl_->search.policy().key(state));
  if (found == memo.end() || found->second.choice < 0) return std::nullopt;
  return found->second.choice;
}

std::size_t OptimalSolver::states() const noexcept { return impl_->search.memo().size(); }

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

}  // namespace ontime
