#include "ontime/allocators/dp.hpp"

#include <optional>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/solve/backtracking_success.hpp"
#include "ontime/solve/concurrent_contiguous_success.hpp"
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
              "start (chains: the devoted policy's exact value)",
          .make_concurrent = [](const ConcurrentMdp& mdp, const ParameterReader&) -> ConcurrentAllocatorFactory {
            ConcurrentContiguousSuccess values(mdp, Aggregation::self);
            const ConcurrentState start = mdp.start();
            int chosen = 0;
            double best = -1;
            for (int k = 0; k < mdp.skeleton_count(); ++k) {
              const double value = ConcurrentMdp::is_live(start, k) ? values.value(start, k) : 0.0;
              if (value > best) {
                best = value;
                chosen = k;
              }
            }
            return eager_commit_factory(mdp, [chosen] { return std::make_unique<DpAllocator>(chosen); });
          }};
}

}  // namespace ontime
