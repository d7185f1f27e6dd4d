#pragma once
// The exact solver: expectimax over the reachable MDP (SPEC §3), memoised.
//
// Computes the maximum success probability V*(s) = max_k sum_o P(o | s, k) V*(o) and the
// choice that attains it, memoised over reachable states. The paper calls this impractical;
// it is the reference every other allocator is measured against (the `optimal` allocator,
// allocators/optimal.hpp, follows it).
//
// Guarantees: the value is exact up to floating-point rounding. Among choices whose values
// differ by at most kTieTolerance the lowest skeleton index wins. Only choices that make
// progress on a skeleton that can still succeed are considered (spending a step idle, or on
// a skeleton that cannot succeed, never raises the success probability), and skeletons that
// share their next action are one choice, named by their lowest index.
//
// Cost: time and memory linear in the number of reachable states, which grows exponentially
// with the number of skeletons (the problem is NP-hard, Theorem 1). States that differ only
// in skeletons that can no longer succeed are merged. Each state takes a hash-table slot of
// 33 bytes (up to 4 skeletons and D <= 253), 49 (up to 10 skeletons) or 99 (beyond); the
// table doubles as it grows, and while it doubles the old and the new table are both held, so
// the peak is about 1.5 times the final table (60 million states of 49 bytes: a table of
// 2^27 slots, 6.3 GiB, and 9.2 GiB at the peak). The solver stops with ResourceLimitError
// when it would hold more than `max_states` states, never by running out of memory.

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "ontime/mdp/mdp.hpp"
#include "ontime/util/memory.hpp"

namespace ontime {

class OptimalSolver {
 public:
  static constexpr double kTieTolerance = 1e-12;
  static constexpr std::size_t kDefaultMaxStates = 10'000'000;

  // Solves nothing yet; the Mdp must outlive the solver, which holds at most `max_states` states.
  explicit OptimalSolver(const Mdp& mdp, std::size_t max_states = kDefaultMaxStates);
  // Frees the memoised states.
  ~OptimalSolver();
  OptimalSolver(const OptimalSolver&) = delete;
  OptimalSolver& operator=(const OptimalSolver&) = delete;
  // Takes over the other solver's states; the other may then only be destroyed or assigned.
  OptimalSolver(OptimalSolver&&) noexcept;
  // Takes over the other solver's states, freeing this one's.
  OptimalSolver& operator=(OptimalSolver&&) noexcept;

  // V*(state) for a running state; solves every state reachable from it that is not yet
  // known. Throws ResourceLimitError at the state cap (the states solved so far are kept).
  double solve(const State& state);

  // The optimal choice in a state already solved, or nullopt if it was not reached.
  std::optional<int> best_choice(const State& state) const;

  // A condition checked every few thousand states while solving: once it returns true, solve
  // throws Cancelled (the states solved so far are kept).
  void set_stop(std::function<bool()> stop);
  // The most memory a solve of `problem` may hold under a cap of `max_states` states: the slot
  // per state (33, 49 or 99 bytes, as above), the table's power-of-two growth and the 1.5 while
  // it grows. Exact evaluation holds the same table.
  static double max_bytes(const Problem& problem, std::size_t max_states);

  // States memoised so far.
  std::size_t states() const noexcept;  // NOLINT(bugprone-exception-escape): see its definition
  std::size_t max_states() const noexcept { return max_states_; }
  const Mdp& mdp() const noexcept { return *mdp_; }

 private:
  struct Impl;
  const Mdp* mdp_;
  std::size_t max_states_;
  std::unique_ptr<Impl> impl_;
};

// Checks, before exact work on `problem` (read from `source`) starts, that the exact solver and
// the exact evaluation take it: InputError naming the source when it has more skeletons than
// kMaxExactSkeletons; UsageError (check_memory_for) when their state cap of `max_states` could
// need more memory than this process can have.
void check_exact_work(const Problem& problem, std::size_t max_states, const std::string& source,
                      const ParameterSpelling& spelling = nullptr);

}  // namespace ontime
