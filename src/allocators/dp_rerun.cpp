#include "ontime/allocators/dp_rerun.hpp"

#include "ontime/allocator_registry.hpp"

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

AllocatorKind dp_rerun_kind() {
  return {
      .name = "dp-rerun",
      .summary = "the paper's DP_Rerun: Eq. (1) re-evaluated before every step, the most promising skeleton refined",
      .capabilities = {Capability::stationary},
      .parameters = {Parameter::choice("aggregation", "sum", {"sum", "max", "self"},
                                       "how Eq. (1) combines the skeletons sharing an action")},
      .make = [](const Mdp& mdp, const ParameterReader& parameters) -> AllocatorFactory {
        auto table =
            std::make_shared<const ContiguousSuccessTable>(mdp, parse_aggregation(parameters.text("aggregation")));
        return [model = &mdp, table] { return std::make_unique<DpRerunAllocator>(*model, table); };
      }};
}

}  // namespace ontime
