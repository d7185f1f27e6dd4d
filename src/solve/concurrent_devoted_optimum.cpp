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
  if (const std::optional<ConcurrentMdp::Move> best = solver_.best_move(devoted)) return *best;
  return ConcurrentContiguousSuccess::devoted_move(*mdp_, state, k);
}

}  // namespace ontime
