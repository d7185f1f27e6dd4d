#include "ontime/allocators/dp.hpp"

#include <memory>
#include <optional>
#include <string_view>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/solve/backtracking_success.hpp"
#include "ontime/solve/concurrent_contiguous_success.hpp"
#include "ontime/solve/concurrent_devoted_optimum.hpp"
#include "ontime/solve/timed_contiguous_success.hpp"

namespace ontime {
namespace {

int best_single_skeleton(const Mdp& mdp) {
  // Eq. (1), or with backtracking (SPEC §7) its extension, or with chains or expiry (SPEC §9) the
  // exact value of refining the skeleton alone, for every skeleton from the start.
  std::optional<ContiguousSuccessTable> table;
  std::optional<BacktrackingSuccess> backtracking;
  std::optional<TimedContiguousSuccess> timed;
  if (mdp.is_timed()) {
    timed.emplace(mdp);
  } else if (mdp.has_backtracking()) {
    backtracking.emplace(mdp, Aggregation::self);
  } else {
    table.emplace(mdp, Aggregation::self);
  }
  const State start = mdp.start();
  int best = 0;
  double best_value = -1;
  for (int k = 0; k < mdp.skeleton_count(); ++k) {
    const double value = table          ? table->success_probability(k, 0, 0, 0)
                         : backtracking ? backtracking->success_probability(start, k)
                                        : timed->expected_reward(start, k);
    if (value > best_value) {
      best_value = value;
      best = k;
    }
  }
  return best;
}

// dp acting while planning with chains or expiry: the devoted optimum of one skeleton, chosen once;
// once that skeleton is dropped, of the live one whose earliest finish is least (ties: lowest
// index), as the eager rule goes on.
class ConcurrentDevotedAllocator final : public ConcurrentAllocator {
 public:
  ConcurrentDevotedAllocator(const ConcurrentMdp& mdp, int chosen) : mdp_(&mdp), devoted_(mdp), chosen_(chosen) {}
  std::string_view name() const noexcept override { return "dp"; }
  ConcurrentMdp::Move choose(const ConcurrentState& state) override {
    const int followed =
        ConcurrentMdp::is_live(state, chosen_) ? chosen_ : soonest_skeleton(*mdp_, state, /*with_work_left=*/false);
    return followed < 0 ? ConcurrentMdp::Move{} : devoted_.move(state, followed);
  }

 private:
  const ConcurrentMdp* mdp_;
  ConcurrentDevotedOptimum devoted_;
  int chosen_;
};

}  // namespace

DpAllocator::DpAllocator(const Mdp& mdp) : chosen_(best_single_skeleton(mdp)) {}

AllocatorKind dp_kind() {
  return {.name = "dp",
          .summary = "the paper's DP: the single skeleton most likely to succeed alone, refined for the whole episode",
          .capabilities = {Capability::stationary, Capability::chains},
          .parameters = {},
          .make = [](const Mdp& mdp, const ParameterReader&) -> AllocatorFactory {
            const int chosen = DpAllocator(mdp).chosen_skeleton();
            return [chosen] { return std::make_unique<DpAllocator>(chosen); };
          },
          .commit_rule =
              "eager along the one skeleton most likely to succeed alone by Eq. (1) acting while planning, from the "
              "start; chains, expiry: the skeleton of the best devoted optimum, followed by it (waiting for a chain "
              "when that pays)",
          .make_concurrent = [](const ConcurrentMdp& mdp, const ParameterReader&) -> ConcurrentAllocatorFactory {
            // With chains or expiry a skeleton is worth its devoted optimum, which the robot follows.
            std::optional<ConcurrentContiguousSuccess> values;
            std::optional<ConcurrentDevotedOptimum> devoted;
            if (mdp.is_timed()) {
              devoted.emplace(mdp);
            } else {
              values.emplace(mdp, Aggregation::self);
            }
            const ConcurrentState start = mdp.start();
            int chosen = 0;
            double best = -1;
            for (int k = 0; k < mdp.skeleton_count(); ++k) {
              double value = 0.0;
              if (ConcurrentMdp::is_live(start, k))
                value = devoted ? devoted->value(start, k) : values->value(start, k);
              if (value > best) {
                best = value;
                chosen = k;
              }
            }
            if (devoted) {
              return [&mdp, chosen] { return std::make_unique<ConcurrentDevotedAllocator>(mdp, chosen); };
            }
            return eager_commit_factory(mdp, [chosen] { return std::make_unique<DpAllocator>(chosen); });
          }};
}

}  // namespace ontime
