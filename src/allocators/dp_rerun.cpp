#include "ontime/allocators/dp_rerun.hpp"

#include <string>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/util/error.hpp"

namespace ontime {

DpRerunAllocator::DpRerunAllocator(const Mdp& mdp, std::optional<Aggregation> aggregation) : mdp_(&mdp) {
  if (mdp.is_timed()) {
    if (aggregation.value_or(Aggregation::self) != Aggregation::self) {
      throw UsageError(std::string("dp-rerun: aggregation '").append(to_string(*aggregation)) +
                       "' has no form with chains or expiry (SPEC §9); 'self' is the one taken");
    }
    timed_ = std::make_unique<TimedContiguousSuccess>(mdp);
  } else if (mdp.has_backtracking()) {
    backtracking_ = std::make_unique<BacktrackingSuccess>(mdp, aggregation.value_or(Aggregation::sum));
  } else {
    table_ = std::make_shared<ContiguousSuccessTable>(mdp, aggregation.value_or(Aggregation::sum));
    worked_on_.reserve(static_cast<std::size_t>(mdp.skeleton_count()));
  }
}

DpRerunAllocator::DpRerunAllocator(const Mdp& mdp, std::shared_ptr<const ContiguousSuccessTable> table)
    : mdp_(&mdp), table_(std::move(table)) {
  worked_on_.reserve(static_cast<std::size_t>(mdp.skeleton_count()));  // no allocation when deciding
}

DpRerunAllocator::DpRerunAllocator(const Mdp& mdp, std::unique_ptr<BacktrackingSuccess> backtracking)
    : mdp_(&mdp), backtracking_(std::move(backtracking)) {}

DpRerunAllocator::DpRerunAllocator(const Mdp& mdp, std::unique_ptr<TimedContiguousSuccess> timed)
    : mdp_(&mdp), timed_(std::move(timed)) {}

int DpRerunAllocator::choose_memoised(const State& state) {
  int best = -1;
  double best_value = -1;
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    if (mdp_->next_action(state, k) < 0) continue;
    const double value = timed_ ? timed_->expected_reward(state, k) : backtracking_->success_probability(state, k);
    if (value > best_value) {
      best_value = value;
      best = k;
    }
  }
  return best < 0 ? 0 : best;
}

int DpRerunAllocator::choose(const State& state) {
  if (backtracking_ || timed_) return choose_memoised(state);
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
      .capabilities = {Capability::stationary, Capability::chains},
      .parameters = {Parameter::choice("aggregation", "sum", {"sum", "max", "self"},
                                       "how Eq. (1) combines the skeletons sharing an action (with chains or expiry "
                                       "only self, the default there)")},
      .make = [](const Mdp& mdp, const ParameterReader& parameters) -> AllocatorFactory {
        const Aggregation aggregation = parse_aggregation(parameters.text("aggregation"));
        if (mdp.is_timed()) {
          if (parameters.given("aggregation") && aggregation != Aggregation::self) {
            throw UsageError("parameter 'aggregation': '" + parameters.text("aggregation") +
                             "' has no form with chains or expiry (SPEC §9); 'self' is the one taken");
          }
          const TimedContiguousSuccess probe(mdp);  // checks the instance's size once, before any episode
          return [model = &mdp] {
            return std::make_unique<DpRerunAllocator>(*model, std::make_unique<TimedContiguousSuccess>(*model));
          };
        }
        if (mdp.has_backtracking()) {
          return [model = &mdp, aggregation] {
            return std::make_unique<DpRerunAllocator>(*model,
                                                      std::make_unique<BacktrackingSuccess>(*model, aggregation));
          };
        }
        auto table = std::make_shared<const ContiguousSuccessTable>(mdp, aggregation);
        return [model = &mdp, table] { return std::make_unique<DpRerunAllocator>(*model, table); };
      },
      .commit_rule =
          "eager along the best skeleton by Eq. (1) acting while planning, the robot working meanwhile (give-ups "
          "blaming a started motion block); chains, expiry: the best skeleton's devoted optimum, which waits for a "
          "chain when that pays",
      .make_concurrent = [](const ConcurrentMdp& mdp, const ParameterReader& parameters) -> ConcurrentAllocatorFactory {
        // With chains or expiry only `self` has a form (the devoted optimum's value): the default there.
        std::optional<Aggregation> aggregation;
        if (parameters.given("aggregation")) aggregation = parse_aggregation(parameters.text("aggregation"));
        ConcurrentContiguousSuccess::check_supported(mdp, aggregation.value_or(Aggregation::self));
        return
            [model = &mdp, aggregation] { return std::make_unique<ConcurrentDpRerunAllocator>(*model, aggregation); };
      }};
}

ConcurrentDpRerunAllocator::ConcurrentDpRerunAllocator(const ConcurrentMdp& mdp, std::optional<Aggregation> aggregation)
    : mdp_(&mdp), values_(mdp, aggregation.value_or(mdp.is_timed() ? Aggregation::self : Aggregation::sum)) {
  if (mdp.is_timed()) devoted_ = std::make_unique<ConcurrentDevotedOptimum>(mdp);
}

ConcurrentMdp::Move ConcurrentDpRerunAllocator::choose(const ConcurrentState& state) {
  int best = -1;
  double best_value = -1.0;
  for (int k = 0; k < mdp_->skeleton_count(); ++k) {
    if (!ConcurrentMdp::is_live(state, k)) continue;
    const double value = devoted_ ? devoted_->value(state, k) : values_.value(state, k);
    if (value > best_value + 1e-12) {
      best_value = value;
      best = k;
    }
  }
  if (best < 0) return {};  // nothing can finish: every move is as good
  return devoted_ ? devoted_->move(state, best) : ConcurrentContiguousSuccess::devoted_move(*mdp_, state, best);
}

}  // namespace ontime
