#pragma once
// `solve_search`: the optimal success probability V* of the start state by branch and bound
// over the reachable MDP, touching only the states whose exact value can still decide a choice;
// a certified interval around V* when a cap or the stop condition ends it first.
//
// What it computes. Depth first from the start, as the memoised solver (optimal_solver.hpp)
// does, but a state's choices are not all solved: each choice c gets an interval
// [lo_c, hi_c] around its value Q(c) = sum_o P(o | s, c) V*(o), from the exact values of the
// successors already solved and, for the others, the certified bounds of ValueBounds (commit
// policy below, clairvoyant relaxation above, each widened by kBoundSlack against rounding).
// The choice with the largest lower end is solved first, exactly; then the choices are
// replayed in index order under the exact solver's tie rule (a choice replaces the best so far
// when its value exceeds it by more than kTieTolerance). A choice whose interval settles its
// comparison (below the best so far plus the tolerance: never the answer; above it: replaces
// it) is not solved. Where the intervals cannot settle a comparison with an exact best so far,
// an upper test first tries to push the choice's upper end below it: the excess is spread over
// its unsolved successors in proportion to their gaps, and each is expanded (not solved) just far
// enough, recursively, to meet its share; the upper bounds it finds are kept. A comparison still
// unsettled solves the one of its two choices not yet exact with the larger hi, and the replay
// starts again. The answer is the last choice the replay keeps, solved exactly.
//
// Guarantees. Every exact value is summed over the same outcomes in the same order from the
// same successor values as the memoised solver's, and a choice is left unsolved only where its
// interval proves the tie rule's verdict on it, so the value and the choice of every state
// solved are the memoised (and layered) solver's to the bit. Under a cap or a stop, the start
// state's interval comes from one step of lookahead over what was solved: lower is at most V*
// (a certified bound, not the value of a policy as the layered solver's is), upper at least V*.
// Deterministic: one thread, the same order every run. Backtracking (SPEC §7) is taken as the
// memoised solver takes it (whole states with their restore values as keys), and so are chains
// and expiry (SPEC §9: keys with the chains' joint state and the timed slots, a success worth its
// plan's expected reward). There ValueBounds' lower end is 0 and its upper end the clairvoyant
// relaxation with every chain-dependent execution 0: still sound, so the value is still exact,
// but looser, so more of the tree is solved than without chains.
//
// Cost: time and memory linear in the states solved or expanded by upper tests (one table of
// both, a slot of the packed key and 16 bytes each) times their outcomes, with a table lookup
// and ValueBounds' O(K) per unsolved successor; the ValueBounds tables ((nodes + sum of
// lengths) * D^2 doubles). The recursion goes one level per step of CT, so at most D deep: a
// deadline above 64 steps runs it on a thread of its own whose stack is sized for D, whatever
// the caller's stack.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "ontime/mdp/mdp.hpp"

namespace ontime {

struct SearchSolveOptions {
  // Records held: a state solved or with an upper bound refined by a test is one, a lower end kept
  // by trials another; 0: no cap.
  std::uint64_t max_states = 0;
  // Checked every few thousand states: once it returns true the search ends as at a cap.
  std::function<bool()> stop;
  // Above 0: no exact search, but trials (BranchAndBoundSearch::trials) until the start's
  // certified interval is at most this wide, or a cap or the stop ends them. At least
  // kFinestGap: below it the trials' backups no longer narrow the interval reliably (the bounds
  // of unsolved successors are widened by 1e-12 against rounding), so solve_search refuses a
  // finer gap (UsageError) rather than stopping wider than asked; 0 asks for the exact search.
  double gap = 0.0;
  static constexpr double kFinestGap = 1e-9;
};

struct SearchSolution {
  double lower = 0;  // V* when exact
  double upper = 0;  // equal to lower when exact
  bool exact = true;
  int first_choice = -1;          // the optimal first choice (cut: the choice of the best lower end), -1 if none
  std::uint64_t states = 0;       // states solved exactly
  std::uint64_t bounded = 0;      // successors valued by their bounds alone (with repetitions)
  std::uint64_t choices_cut = 0;  // choices left unsolved because their interval settled them
  std::uint64_t tested = 0;       // upper tests run (states expanded to refine their upper bound)
  std::uint64_t refined = 0;      // states holding a refined upper bound at the end
  std::string stopped_by;         // cut: the cap or stop that ended the search (trials: or "the gap")
};

// The search kept between calls, for deciding step by step (the `branch-and-bound` allocator):
// the values it solved and the upper bounds it refined hold for any state, so a later search
// from a successor starts from them.
class BranchAndBoundSearch {
 public:
  // Builds ValueBounds' tables. Throws as solve_search does.
  explicit BranchAndBoundSearch(const Mdp& mdp, std::uint64_t max_states = 0);
  ~BranchAndBoundSearch();
  BranchAndBoundSearch(const BranchAndBoundSearch&) = delete;
  BranchAndBoundSearch& operator=(const BranchAndBoundSearch&) = delete;
  BranchAndBoundSearch(BranchAndBoundSearch&&) noexcept;
  BranchAndBoundSearch& operator=(BranchAndBoundSearch&&) noexcept;

  // Searches from `from` until its value is exact, the state cap is reached (records held since
  // made or cleared: see size()) or `stop(work)` returns true, checked every `check_interval` units of
  // work (a state solved, or expanded by an upper test) with the units done in this call. Cut
  // short, the solution is `from`'s interval and the choice of the best lower end: `lower` is at
  // most that choice's value, `upper` at least V*(from), so upper - lower bounds its loss. The
  // counters are cumulative.
  SearchSolution search(const State& from, const std::function<bool(std::uint64_t work)>& stop = nullptr,
                        std::uint64_t check_interval = 1);
  // Trials of bounded RTDP (McMahan, Likhachev and Gordon 2005) from `from`, each expanded state
  // one unit of work, until `stop(work)` returns true (checked every `check_interval` units), the
  // state cap is reached or from's interval is at most `gap` (at least SearchSolveOptions::kFinestGap) wide. A trial
  // walks down by the choice of the largest upper end and an outcome drawn in proportion to probability times gap (from
  // the seed of the last clear(), 1 before any), and backs both ends up along its path: where the depth-first search
  // spends its work deep in one choice, trials spread it over the choices that may still be best, so that their lower
  // ends rise. The lower ends are certified (at most the exact solver's values) and kept like the upper ones; a
  // search() after trials settles choices by them. Returns from's interval and the choice of the best lower end (exact
  // when `from` was solved before).
  SearchSolution trials(const State& from, const std::function<bool(std::uint64_t work)>& stop,
                        std::uint64_t check_interval = 1, double gap = 0.0);
  // Forgets what was solved and refined; the trials draw from `seed` on.
  void clear(std::uint64_t seed = 1);
  // Records held, what the cap counts: a state solved or refined is one, a lower end kept by the
  // trials another.
  std::uint64_t size() const noexcept;  // NOLINT(bugprone-exception-escape): see its definition

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Solves from mdp.start(). Throws UsageError for a gap that is neither 0 nor within
// [kFinestGap, 1], for more than kMaxExactSkeletons skeletons (or more
// blamable actions than the exact solvers' keys hold); ResourceLimitError when ValueBounds'
// tables are too large.
SearchSolution solve_search(const Mdp& mdp, const SearchSolveOptions& options = {});

}  // namespace ontime
