#include "ontime/solve/concurrent_devoted_optimum.hpp"

#include <optional>

#include "ontime/solve/concurrent_contiguous_success.hpp"

namespace ontime {

ConcurrentDevotedOptimum::ConcurrentDevotedOptimum(const ConcurrentMdp& mdp, std::size_t max_states)
    : mdp_(&mdp), solver_(mdp, max_states) {}

double ConcurrentDevotedOptimum::value(const ConcurrentState& state, int k) {
  if (!ConcurrentMdp::is_live(state, k)) return 0.0;
  return solver_.solve(mdp_->devoted_to(state, k));
}

ConcurrentMdp::Move ConcurrentDevotedOptimum::move(const ConcurrentState& state, int k) {
  const ConcurrentState devoted = mdp_->devoted_to(state, k);
  (void)solver_.solve(devoted);
  const std::optional<ConcurrentMdp::Move> best = solver_.best_move(devoted);
  if (!best) return ConcurrentContiguousSuccess::devoted_move(*mdp_, state, k);
  if (best->is_start() || best->refine != ConcurrentMdp::kWait || mdp_->has_backtracking()) return *best;
  // The devoted planner idles (k and its prefixes are refined in full): the planner refines the first
  // group of the state with work left instead, which changes nothing along k.
  const ChoiceList choices = mdp_->refine_choices(state);
  return choices.empty() ? *best : ConcurrentMdp::Move{-1, choices[0]};
}

}  // namespace ontime
