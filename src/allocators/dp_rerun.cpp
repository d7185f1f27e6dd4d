#include "ontime/allocators/dp_rerun.hpp"

namespace ontime {

DpRerunAllocator::DpRerunAllocator(const Mdp& mdp, Aggregation aggregation)
    : mdp_(&mdp), table_(std::make_shared<ContiguousSuccessTable>(mdp, aggregation)) {}

DpRerunAllocator::DpRerunAllocator(const Mdp& mdp, std::shared_ptr<const ContiguousSuccessTable> table) noexcept
    : mdp_(&mdp), table_(std::move(table)) {}

int DpRerunAllocator::choose(const State& state) {
  int best = -1;
  double best_value = -1;
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    if (mdp_->next_action(state, k) < 0) continue;
    const double value = table_->success_probability(state, k);
    if (value > best_value) {
      best_value = value;
      best = k;
    }
  }
  return best < 0 ? 0 : best;
}

}  // namespace ontime
