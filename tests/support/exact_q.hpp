#pragma once
// Q*(s, c) for tests of allocators: the exact value of choosing c in s and then playing optimally.

#include "ontime/mdp/mdp.hpp"
#include "ontime/solve/optimal_solver.hpp"

namespace ontime::testing {

inline double exact_q(const Mdp& mdp, OptimalSolver& solver, const State& state, int choice) {
  double q = 0.0;
  mdp.for_each_outcome(state, choice, [&](double probability, Status status, const State& next) {
    if (status == Status::success) q += probability;
    if (status == Status::running) q += probability * solver.solve(next);
  });
  return q;
}

}  // namespace ontime::testing
