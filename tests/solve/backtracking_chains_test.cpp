// Backtracking (SPEC §7) together with exogenous chains and actions that expire (SPEC §9): the
// MDP's transition on a case worked by hand, the memoised solver and exact evaluation against the
// independent reference recursion, the layered solver and the search against the memoised solver
// to the bit, the bounds, and every allocator and simulated episodes on such instances.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/solve/layered_solver.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/random.hpp"
#include "support/chain_reference.hpp"
#include "support/exact_solver_checks.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

// A random instance that backtracks, with random chains, expiry and (odd seeds) rewards.
Problem backtracking_chains_case(std::uint64_t seed, int skeletons, int length, Steps deadline) {
  return testing::with_random_chains(
      testing::with_backtracking(testing::random_instance(seed, skeletons, length, deadline), seed + 1000), seed + 2000,
      seed % 2 == 1);
}

double exact_optimum(const Problem& problem) {
  const Mdp mdp(problem);
  OptimalSolver solver(mdp);
  return solver.solve(mdp.start());
}

// The timed slots follow the culprits' in one restore array; a backtrack moves the chains as any
// step does, restores ET to the execution before the culprit and zeroes the culprit's slots of
// both kinds.
TEST(BacktrackingWithChains, ABacktrackMovesTheChainsAndClearsTheCulpritsSlots) {
  const Problem problem = testing::door_and_regrasp();
  ASSERT_TRUE(problem.has_backtracking());
  ASSERT_TRUE(problem.is_timed());
  const int a = problem.find_action("a");
  EXPECT_EQ(problem.culprit_slot_count(), 1);
  EXPECT_EQ(problem.timed_slot_count(), 1);
  EXPECT_EQ(problem.culprit_slot(a), 0);
  EXPECT_EQ(problem.timed_slot(a), 1);
  const Mdp mdp(problem);
  State state = mdp.start();
  EXPECT_EQ(mdp.apply(state, 0, Observation::found(2).with_chains(1)), Status::running);  // z
  State after_z = state;
  EXPECT_EQ(mdp.apply(state, 0, Observation::found(2).with_chains(0)), Status::running);  // a
  EXPECT_EQ(state.execution[0], 4);
  EXPECT_EQ(state.restore[0], 2);  // B_a as a culprit
  EXPECT_EQ(state.restore[1], 2);  // and as a timed action
  // b's attempt gives up in step 3, with the door locked again: the state after z, two steps on.
  EXPECT_EQ(mdp.apply(state, 0, Observation::backtracked(a).with_chains(1)), Status::running);
  after_z.time = 3;
  EXPECT_EQ(state, after_z);
  // Every refinement of the plan takes an even number of steps, so a starts at an even step, with
  // the door open; the plan fails only if it is completed after step 15: b gives up six times.
  const double best = exact_optimum(problem);
  EXPECT_DOUBLE_EQ(best, 1.0 - std::pow(0.5, 6));
  EXPECT_NEAR(best, testing::ChainReferenceSolver(problem).optimum(), 1e-12);
}

// A rule that reads the clock and the chains: skeleton (2 CT + joint state) mod K.
class ClockTwiceAndChains final : public Allocator {
 public:
  explicit ClockTwiceAndChains(int skeletons) : skeletons_(skeletons) {}
  std::string_view name() const noexcept override { return "clock-twice-and-chains"; }
  int choose(const State& state) override { return (2 * state.time + state.chains) % skeletons_; }

 private:
  int skeletons_;
};

// The memoised solver's optimum and exact evaluation of a rule equal the reference recursion's,
// which cuts the skeletons back itself and follows every path of the chains; backtracking moves
// the optimum on most instances, so the comparison sees it.
TEST(BacktrackingWithChains, ExactValuesEqualTheReferenceRecursion) {
  const int count = testing::repetitions_to_check(80);
  int backtracking = 0, moved = 0, valued = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Problem problem = backtracking_chains_case(seed, 3, 4, 8);
    ASSERT_TRUE(problem.is_timed());
    if (!problem.has_backtracking()) continue;
    ++backtracking;
    testing::ChainReferenceSolver reference(problem);
    const double best = exact_optimum(problem);
    EXPECT_NEAR(best, reference.optimum(), 1e-12);
    valued += best > 0 ? 1 : 0;
    const Problem without = testing::with_random_chains(testing::random_instance(seed, 3, 4, 8), seed + 2000,
                                                        seed % 2 == 1);  // the same instance, never giving up
    moved += std::abs(exact_optimum(without) - best) > 1e-9 ? 1 : 0;

    const Mdp mdp(problem);
    ClockTwiceAndChains rule(problem.skeleton_count());
    const double exact = evaluate_exactly(mdp, rule).expected_reward;
    EXPECT_NEAR(exact, reference.value_of([&](const testing::ChainReferenceSolver::Node& node) {
      return (2 * node.time + reference.joint(node)) % problem.skeleton_count();
    }),
                1e-12);
    EXPECT_LE(exact, best + 1e-12);
  }
  EXPECT_GT(backtracking, count / 2);
  EXPECT_GT(valued, backtracking / 4) << valued << " of " << backtracking;  // not a comparison of zeros
  EXPECT_GT(moved, valued / 3) << moved << " of " << valued;                // backtracking changes the value
}

// The layered solver and the search hold both kinds of restore values and the chains in their
// keys: the memoised solver's value, choice and states to the bit.
TEST(BacktrackingWithChains, TheLayeredSolverAndTheSearchEqualTheMemoisedOneBitForBit) {
  const int count = testing::repetitions_to_check(40);
  int large = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Problem problem = backtracking_chains_case(seed + 300, 4, 4, 14);
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    solver.solve(mdp.start());
    large += solver.states() >= 30 ? 1 : 0;
    testing::expect_layered_equals_memoised(mdp);
    testing::expect_search_equals_memoised(mdp);
  }
  EXPECT_GT(large, count / 4) << large;
}

// The upper bound composes both relaxations (a give-up counts as a success worth the largest
// reward; a chain-dependent execution takes 0 steps and nothing expires): it holds the optimum in
// every state random episodes visit, and a layered cap's interval holds it.
TEST(BacktrackingWithChains, TheBoundsAndEveryCapsIntervalHoldTheOptimum) {
  const int count = testing::repetitions_to_check(30);
  int states = 0, cut = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Problem problem = backtracking_chains_case(seed + 600, 4, 4, 16);
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    const ValueBounds bounds(mdp);
    const double best = solver.solve(mdp.start());
    SplitMix64 generator(seed);
    for (int episode = 0; episode < 20; ++episode) {
      State state = mdp.start();
      for (Status status = Status::running; status == Status::running;) {
        EXPECT_GE(bounds.upper(state), solver.solve(state) - 1e-12);
        EXPECT_EQ(bounds.lower(state), 0.0);
        ++states;
        const ChoiceList choices = mdp.useful_choices(state);
        if (choices.empty()) break;
        const int choice = choices[generator() % choices.size()];
        status = mdp.apply(state, choice, mdp.sample_observation(state, choice, generator));
      }
    }
    if (solver.states() < 30) continue;  // too few layers to cut
    ++cut;
    for (const std::uint64_t cap : {std::uint64_t{3}, solver.states() / 3}) {
      LayeredSolveOptions options;
      options.max_states = cap;
      const LayeredSolution layered = solve_layered(mdp, options);
      EXPECT_FALSE(layered.exact) << "cap " << cap;
      EXPECT_LE(layered.lower, best + 1e-12) << "cap " << cap;
      EXPECT_GE(layered.upper, best - 1e-12) << "cap " << cap;
    }
  }
  EXPECT_GT(states, count * 20);
  EXPECT_GE(cut, count / 4) << cut << " " << states;
}

// Every allocator of the registry decides on such instances. Simulated episodes (the hidden
// world draws each attempt, the session the chains) agree with the exact value of the stationary
// ones, which stays below the optimum; the others' mean rewards stay below it within sampling
// error. (ppo needs a trained policy: tests/learn/ppo_test.cpp.)
TEST(BacktrackingWithChains, EveryAllocatorDecidesAndEpisodesAgreeWithTheExactValues) {
  const AllocatorRegistry& registry = allocator_registry();
  const int count = testing::repetitions_to_check(3);
  int instances = 0, stationary = 0;
  for (std::uint64_t seed = 1; instances < count; ++seed) {
    const Problem problem = backtracking_chains_case(seed + 900, 3, 3, 8);
    if (!problem.has_backtracking() || exact_optimum(problem) < 0.2) continue;
    ++instances;
    const Mdp mdp(problem);
    const double best = exact_optimum(problem);
    for (const std::string& name : registry.names({}, {Capability::needs_policy})) {
      SCOPED_TRACE("seed " + std::to_string(seed) + " " + name);
      const ParameterValues values = name == "mcts" ? ParameterValues{{"iterations", "200"}} : ParameterValues{};
      const AllocatorFactory factory = make_allocator_factory(name, mdp, values);
      MonteCarloOptions options;
      options.episodes = name == "mcts" || name == "branch-and-bound" ? 1'000 : 4'000;
      options.seed = seed;
      options.threads = 1;
      const MonteCarloResult sampled = run_monte_carlo(mdp, factory, options);
      const auto error = [&](double value) {
        return 4 * std::sqrt(std::max(value * (1 - value), 1e-4) / static_cast<double>(options.episodes));
      };
      EXPECT_LE(sampled.mean_reward, best + error(best));
      if (registry.find(name).capabilities.has(Capability::stationary)) {
        ++stationary;
        const double exact = evaluate_exactly(mdp, *factory()).expected_reward;
        EXPECT_LE(exact, best + 1e-12);
        EXPECT_NEAR(sampled.mean_reward, exact, error(exact));
      }
    }
  }
  EXPECT_GE(stationary, count * 4);
}

}  // namespace
}  // namespace ontime
