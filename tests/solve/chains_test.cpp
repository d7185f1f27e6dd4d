// Exogenous chains and actions that expire (SPEC §9) in the MDP, the memoised exact solver and
// exact evaluation: each against the independent reference recursion on random instances and
// on cases valued by hand; what does not model them yet refuses them.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/solve/layered_solver.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/solve/search_solver.hpp"
#include "ontime/util/error.hpp"
#include "support/chain_reference.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

double optimum(const Problem& problem) {
  const Mdp mdp(problem);
  OptimalSolver solver(mdp);
  return solver.solve(mdp.start());
}

TEST(Chains, TheSolverValuesHandMadeCases) {
  EXPECT_DOUBLE_EQ(optimum(testing::queue_wait_instance("")), 0.7);
  EXPECT_EQ(optimum(testing::queue_wait_instance(R"(, "expires": {"after": 0})")), 0.0);
  EXPECT_DOUBLE_EQ(optimum(testing::queue_wait_instance(R"(, "expires": {"after": 1})")), 0.7);
  EXPECT_DOUBLE_EQ(optimum(testing::queue_wait_instance(R"(, "expires": {"chain": "queue", "states": ["long"]})")),
                   0.7);
  // Blocked while short: only the long queue's start is allowed, and it ends too late.
  EXPECT_EQ(optimum(testing::queue_wait_instance(R"(, "expires": {"chain": "queue", "states": ["short"]})")), 0.0);
}

TEST(Chains, WaitingForADoorIsAChoice) {
  const Problem problem = testing::door_open_at_even_steps();
  EXPECT_EQ(optimum(problem), 1.0);
  EXPECT_EQ(testing::ChainReferenceSolver(problem).optimum(), 1.0);
  const Mdp mdp(problem);
  OptimalSolver solver(mdp);
  solver.solve(mdp.start());
  EXPECT_EQ(solver.best_choice(mdp.start()), 1);  // wait first
}

TEST(Chains, AStepMovesTheChainsWhateverTheRobotDoes) {
  const Problem problem = testing::queue_wait_instance("");
  const Mdp mdp(problem);
  State state = mdp.start();
  EXPECT_EQ(state.chains, 0);  // short
  ASSERT_EQ(mdp.joint_chain_states(), 2);
  double total = 0;
  std::vector<std::uint16_t> next;
  mdp.for_each_observation(state, 0, [&](double probability, const Observation& observation) {
    total += probability;
    next.push_back(observation.chains);
  });
  EXPECT_DOUBLE_EQ(total, 1.0);
  EXPECT_EQ(next, (std::vector<std::uint16_t>{0, 1}));  // the motion is found in step 1, then short or long
  EXPECT_EQ(mdp.apply(state, 0, Observation::found(0).with_chains(1)), Status::success);
  EXPECT_EQ(state.chains, 1);
  EXPECT_EQ(mdp.success_reward(state, 0), 0.0);  // long at step 1: done at 6 > 4
  EXPECT_THROW(mdp.apply(state, 0, Observation::not_yet().with_chains(2)), UsageError);
}

TEST(Chains, TheOptimumIsTheReferenceSolversExpectedReward) {
  int timed = 0;
  int valued = 0;
  const int count = testing::repetitions_to_check(120);
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const Problem problem = testing::with_random_chains(testing::random_instance(seed, 3, 3, 8), seed, seed % 2 == 0);
    ASSERT_TRUE(problem.is_timed());
    timed += problem.timed_slot_count();
    const double expected = testing::ChainReferenceSolver(problem).optimum();
    valued += expected > 0 ? 1 : 0;
    EXPECT_NEAR(optimum(problem), expected, 1e-12) << "seed " << seed;
  }
  EXPECT_GT(timed, count);            // timed actions are well represented
  EXPECT_GT(valued, count * 5 / 12);  // and about half the instances can succeed
}

// A stationary rule that reads the clock and the chains: skeleton (CT + joint state) mod K.
class ClockAndChains final : public Allocator {
 public:
  explicit ClockAndChains(int skeletons) : skeletons_(skeletons) {}
  std::string_view name() const noexcept override { return "clock-and-chains"; }
  int choose(const State& state) override { return (state.time + state.chains) % skeletons_; }

 private:
  int skeletons_;
};

TEST(Chains, ExactEvaluationOfARuleIsTheReferencesValue) {
  const int count = testing::repetitions_to_check(100);
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const Problem problem =
        testing::with_random_chains(testing::random_instance(seed + 500, 3, 3, 8), seed + 500, seed % 2 == 1);
    const Mdp mdp(problem);
    ClockAndChains rule(problem.skeleton_count());
    const ExactEvaluation exact = evaluate_exactly(mdp, rule);
    const auto joint = [&problem](const testing::ChainReferenceSolver::Node& node) {
      int value = 0;
      int stride = 1;
      for (std::size_t c = 0; c < node.chains.size(); ++c) {
        value += node.chains[c] * stride;
        stride *= problem.chains()[c].state_count();
      }
      return value;
    };
    const double expected =
        testing::ChainReferenceSolver(problem).value_of([&](const testing::ChainReferenceSolver::Node& node) {
          return (node.time + joint(node)) % problem.skeleton_count();
        });
    EXPECT_NEAR(exact.expected_reward, expected, 1e-12) << "seed " << seed;
    EXPECT_LE(exact.expected_reward, optimum(problem) + 1e-12) << "seed " << seed;
  }
}

TEST(Chains, WhatDoesNotModelThemYetRefusesThem) {
  const Problem problem = testing::queue_wait_instance("");
  const Mdp mdp(problem);
  EXPECT_THROW(solve_layered(mdp), UsageError);
  EXPECT_THROW(solve_search(mdp), UsageError);
  const AllocatorRegistry& registry = allocator_registry();
  EXPECT_THROW(registry.make_factory("branch-and-bound", mdp, {}), UsageError);
  for (const char* name : {"optimal", "round-robin", "dp", "dp-rerun", "greedy", "thompson", "mcts"}) {
    EXPECT_NO_THROW(registry.make_factory(name, mdp, {})) << name;
  }
}

}  // namespace
}  // namespace ontime
