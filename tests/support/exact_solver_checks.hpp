#pragma once
// Checks shared by the tests of the exact solvers: the layered solver and the search against the
// memoised solver on one instance, to the bit; the layered solver's refusals.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>

#include "ontime/mdp/mdp.hpp"
#include "ontime/solve/layered_solver.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/solve/search_solver.hpp"
#include "ontime/util/error.hpp"

namespace ontime::testing {

// The plan-first optimum of `problem` (SPEC §2), by the memoised solver.
inline double memoised_optimum(const Problem& problem) {
  const Mdp mdp(problem);
  OptimalSolver solver(mdp);
  return solver.solve(mdp.start());
}

// The layered solver on 1 and 2 threads: the memoised solver's value to the bit, its first
// choice and state count, and the policy of the first 3 layers holds whole states (they solve
// to its values and choices).
inline void expect_layered_equals_memoised(const Mdp& mdp) {
  OptimalSolver solver(mdp);
  const double optimum = solver.solve(mdp.start());
  for (const unsigned threads : {1U, 2U}) {
    LayeredSolveOptions options;
    options.threads = threads;
    options.policy_layers = 3;
    const LayeredSolution layered = solve_layered(mdp, options);
    ASSERT_TRUE(layered.exact);
    EXPECT_EQ(layered.lower, optimum);
    EXPECT_EQ(layered.upper, optimum);
    EXPECT_EQ(layered.first_choice, solver.best_choice(mdp.start()).value_or(-1));
    EXPECT_EQ(layered.states, solver.states());
    ASSERT_FALSE(layered.policy.empty());
    for (const PolicyEntry& entry : layered.policy) {
      EXPECT_EQ(entry.lower, solver.solve(entry.state));
      EXPECT_EQ(entry.choice, solver.best_choice(entry.state).value_or(-1));
    }
  }
}

// The search: the memoised solver's value to the bit and its first choice, touching no more
// states; after trials of 2 and 20 units too (their interval holds the optimum); a cap at half
// its states gives an interval that holds the optimum.
inline void expect_search_equals_memoised(const Mdp& mdp) {
  OptimalSolver solver(mdp);
  const double optimum = solver.solve(mdp.start());
  const SearchSolution search = solve_search(mdp);
  ASSERT_TRUE(search.exact);
  EXPECT_EQ(search.lower, optimum);
  EXPECT_EQ(search.first_choice, solver.best_choice(mdp.start()).value_or(-1));
  EXPECT_LE(search.states, solver.states());
  for (const std::uint64_t budget : {2U, 20U}) {
    BranchAndBoundSearch trialled(mdp);
    const SearchSolution trials = trialled.trials(mdp.start(), [&](std::uint64_t work) { return work >= budget; });
    EXPECT_LE(trials.lower, optimum + OptimalSolver::kTieTolerance);  // as SearchSolver.Trials* says
    // (A success probability of 1 may sum to 1 + 1 ulp in the memoised solver, while the bound
    // is capped at the largest reward: a few ulps of slack.)
    EXPECT_GE(trials.upper, optimum - 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, optimum));
    const SearchSolution after = trialled.search(mdp.start());
    EXPECT_EQ(after.lower, optimum);
    EXPECT_EQ(after.first_choice, search.first_choice);
  }
  SearchSolveOptions capped;
  capped.max_states = search.states / 2 + 1;
  const SearchSolution cut = solve_search(mdp, capped);
  EXPECT_LE(cut.lower, optimum + 1e-15);
  EXPECT_GE(cut.upper, optimum - 1e-15);
}

// The layered solver refuses a tolerance and a split (both bound a success probability read from
// the static distributions: not a reward, nor chains or expiry).
inline void expect_layered_refuses_a_tolerance_and_a_split(const Mdp& mdp) {
  LayeredSolveOptions options;
  options.tolerance = 1e-3;
  EXPECT_THROW(solve_layered(mdp, options), UsageError);
  options.tolerance = 0;
  options.split = SplitMode::always;
  EXPECT_THROW(solve_layered(mdp, options), UsageError);
}

}  // namespace ontime::testing
