#pragma once
// `ConcurrentSearch`: an anytime search of the acting-while-planning MDP (SPEC §10) from a state,
// with a certified interval on V* there and a move whose loss it bounds.
//
// What it computes. Trials of bounded RTDP (McMahan, Likhachev and Gordon 2005) over the states of
// ConcurrentMdp: every state met holds an interval [lo, hi] around V*, first the bounds of
// ConcurrentValueBounds (widened by kBoundSlack against rounding, unless they meet: then the value
// is the devoted policy's, exact), then the backups of its moves (ConcurrentMdp::useful_moves):
// Q_lo(m) and Q_hi(m) the expectations of the successors' ends over the move's outcomes (a step's,
// or a start's: one, or with an execution a chain draws when the action starts, one per execution
// time, ConcurrentMdp::for_each_start_outcome; an outcome that ends the episode is worth its
// reward), lo = max_m Q_lo(m), hi = max_m Q_hi(m), each kept no looser than before. A
// trial walks down from the state by the move of the largest Q_hi (ties: the first) and an outcome
// drawn in proportion to probability times gap (from the seed of the last clear(), 1 before any),
// backs the intervals up along its path, and stops at a state whose interval has closed or whose
// move's outcomes hold at most 1/kTrialRatio of the start's gap in probability times gap (bounded
// RTDP's tau). Always taking the outcome of the largest probability times gap instead walks the
// same paths again and again once their backups stop moving: on the kitchen
// (data/instances/manipulation.json) the start's interval stood at [0.6686, 0.7991] after 60 s
// that way, and narrows to [0.7366, 0.7637] in the same time with the draws.
//
// Guarantees. Every lo is at most V* and every hi at least V* (the bounds are certified and a
// backup of certified bounds is certified), so the answer's `upper - lower` is at least the loss
// V*(from) - Q*(from, move) of its move. Trials enter open states only. Were their backups to
// stop moving every bound, each state a trial may reach would have hi - lo at most the summed
// probability times gap of its move of the largest Q_hi, and unrolling that from `from` would
// make from's gap at most 1/kTrialRatio of itself (docs/theory.md, "The search"); so the
// intervals keep narrowing, and, the state space being finite and acyclic (a step raises CT, a
// start lengthens E), without a limit the search ends with from's interval closed: the value is
// V* (up to rounding) and the move is one that attains it. The move is the one of the largest
// Q_lo in the order of useful_moves, a later move replacing it only when better by more than
// ConcurrentSolver::kTieTolerance, the exact solver's rule.
//
// Cost: one unit of work per state backed up (its moves' outcomes, a table lookup or a bound each);
// memory: one record (the state's words, two doubles and a hash-table slot) per state met, kept
// across calls so that later searches from successors start from them; see size().

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/solve/concurrent_value_bounds.hpp"
#include "ontime/solve/layered_solver.hpp"

namespace ontime {

struct ConcurrentSearchResult {
  ConcurrentMdp::Move move;  // the move of the best certified lower end (the default Move: none)
  double lower = 0;          // that move's certified lower end: at most Q*(from, move)
  double upper = 0;          // at least V*(from)
  bool exact = false;        // from's interval closed: lower is V*(from), the move optimal
  std::uint64_t work = 0;    // states backed up in this call
};

class ConcurrentSearch {
 public:
  // Widening of the bounds of a state first met, against rounding.
  static constexpr double kBoundSlack = 1e-12;
  // A trial ends where its move's outcomes hold at most 1/kTrialRatio of the start's gap, in
  // probability times gap (the factor of the plan-first trials; not tuned to any instance).
  static constexpr double kTrialRatio = 32.0;

  // A search of `mdp` (which must outlive it) that stops once it holds `max_states` records (0:
  // no cap).
  explicit ConcurrentSearch(const ConcurrentMdp& mdp, std::uint64_t max_states = 0);
  ~ConcurrentSearch();
  ConcurrentSearch(const ConcurrentSearch&) = delete;
  ConcurrentSearch& operator=(const ConcurrentSearch&) = delete;

  // Trials from `from` (a state with some skeleton live) until its interval closes, the record
  // cap is reached or `stop(work)` returns true (checked after every unit of work, with the units
  // done in this call); then the move of the best lower end and from's interval.
  ConcurrentSearchResult search(const ConcurrentState& from, const std::function<bool(std::uint64_t work)>& stop);
  // The certified interval around V*(state) held for `state` (any state of the MDP): exact when
  // terminal, else its record's, else ConcurrentValueBounds' (widened by kBoundSlack unless they
  // meet), then kept as its record.
  ConcurrentValueBounds::Interval interval(const ConcurrentState& state);
  // Forgets every record; the trials draw from `seed` on.
  void clear(std::uint64_t seed = 1);
  // Records held: one per state met.
  std::uint64_t size() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct ConcurrentSolveOptions {
  enum class Method { memoised, search };
  Method method = Method::memoised;
  // States held (memoised: states solved; search: each of those and each record of an interval);
  // 0: ConcurrentSolver::kDefaultMaxStates.
  std::uint64_t max_states = 0;
  // Search only, above 0: no exact search, but trials until the start's interval is at most this
  // wide (or the cap or the stop ends them); 0: the exact search.
  double gap = 0.0;
  // Checked every few thousand states: the search ends as at a cap; the memoised solver throws
  // Cancelled.
  std::function<bool()> stop;
};

struct ConcurrentSolution {
  double lower = 0;  // V* when exact
  double upper = 0;  // equal to lower when exact
  bool exact = false;
  ConcurrentMdp::Move first;  // the optimal first move (else: that of the best lower end)
  std::uint64_t solved = 0;   // states solved exactly
  std::uint64_t records = 0;  // search: states holding an interval
  // When not exact: "the gap", "the state cap", "the stop condition" (layered: also "the memory cap", "the disk cap").
  std::string stopped_by;
  // solve_concurrent_layered only: the level whose states got bounds when cut (-1: none), the figures
  // of each level, the most memory its levels and tables held and the most scratch it wrote.
  int frontier_layer = -1;
  std::vector<LayerFigures> layers;
  std::uint64_t peak_memory_bytes = 0;
  std::uint64_t peak_disk_bytes = 0;
};

// The optimum of acting while planning from the start (`ontime solve --act concurrent`, Python's
// `solve(act='concurrent')`), by either method:
//  - memoised: ConcurrentSolver; always exact; ResourceLimitError past the cap.
//  - search: branch and bound (ConcurrentSolver::set_bounds) over the intervals of a
//    ConcurrentSearch whose trials run first; the value and the first move to the bit the
//    memoised solver's. With a gap, trials of bounded RTDP until the start's certified interval is
//    that narrow. Where the cap or the stop ends it, the start's certified interval from the
//    records (lower: a certified bound, not a policy's value). Takes backtracking (SPEC §7), chains
//    and expiry (SPEC §9), as ConcurrentValueBounds does.
// Cost: the search's time and memory are linear in the states it solves or bounds (a
// ConcurrentSolver entry or a ConcurrentSearch record each); it solves at most the memoised
// solver's states, far fewer where the bounds are tight. The third method, level by level with the
// plan-first layered solver's options, is solve_concurrent_layered (concurrent_layered_solver.hpp).
ConcurrentSolution solve_concurrent(const ConcurrentMdp& mdp, const ConcurrentSolveOptions& options);

}  // namespace ontime
