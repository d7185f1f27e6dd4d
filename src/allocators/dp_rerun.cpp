#include "ontime/allocators/dp_rerun.hpp"

#include "ontime/allocators/allocator_registry.hpp"

namespace ontime {

DpRerunAllocator::DpRerunAllocator(const Mdp& mdp, Aggregation aggregation) : mdp_(&mdp) {
  if (mdp.has_backtracking()) {
    backtracking_ = std::make_unique<BacktrackingSuccess>(mdp, aggregation);
  } else {
    table_ = std::make_shared<ContiguousSuccessTable>(mdp, aggregation);
    worked_on_.reserve(static_cast<std::size_t>(mdp.skeleton_count()));
  }
}

DpRerunAllocator::DpRerunAllocator(const Mdp& mdp, std::shared_ptr<const ContiguousSuccessTable> table)
    : mdp_(&mdp), table_(std::move(table)) {
  worked_on_.reserve(static_cast<std::size_t>(mdp.skeleton_count()));  // no allocation when deciding
}

DpRerunAllocator::DpRerunAllocator(const Mdp& mdp, std::unique_ptr<BacktrackingSuccess> backtracking)
    : mdp_(&mdp), backtracking_(std::move(backtracking)) {}

int DpRerunAllocator::choose_with_backtracking(const State& state) {
  int best = -1;
  double best_value = -1;
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    if (mdp_->next_action(state, k) < 0) continue;
    const double value = backtracking_->success_probability(state, k);
    if (value > best_value) {
      best_value = value;
      best = k;
    }
  }
  return best < 0 ? 0 : best;
}

int DpRerunAllocator::choose(const State& state) {
  if (backtracking_) return choose_with_backtracking(state);
  // The largest PS, ties to the lowest index. Skeletons worked on (PT_k > 0) need a dot product:
  // they are left for a second pass, where those whose bound is below the best are skipped.
  int best = -1;
  double best_value = -1;
  worked_on_.clear();
  const std::uint8_t* refined = state.refined.data();
  const std::uint16_t* spent = state.spent.data();
  const std::uint16_t* execution = state.execution.data();
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    if (mdp_->next_action(state, k) < 0) continue;
    if (spent[k] != 0) {
      worked_on_.push_back(k);
      continue;
    }
    const double value = table_->fresh_success_probability(k, refined[k], std::int64_t{state.time} + execution[k]);
    if (value > best_value) {
      best_value = value;
      best = k;
    }
  }
  for (const int k : worked_on_) {
    if (table_->upper_bound(k, refined[k], std::int64_t{state.time} + execution[k]) < best_value) continue;
    const double value = table_->success_probability(state, k);
    if (value > best_value || (value == best_value && k < best)) {
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
        const Aggregation aggregation = parse_aggregation(parameters.text("aggregation"));
        if (mdp.has_backtracking()) {
          return [model = &mdp, aggregation] {
            return std::make_unique<DpRerunAllocator>(*model,
                                                      std::make_unique<BacktrackingSuccess>(*model, aggregation));
          };
        }
        auto table = std::make_shared<const ContiguousSuccessTable>(mdp, aggregation);
        return [model = &mdp, table] { return std::make_unique<DpRerunAllocator>(*model, table); };
      }};
}

}  // namespace ontime
