// Exogenous chains and actions that expire (SPEC §9) in the MDP, the memoised exact solver and
// exact evaluation, each against the independent reference recursion on random instances and on
// cases valued by hand; the layered solver against the memoised one; what does not model them
// yet refuses them.
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
#include "support/exact_solver_checks.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

using testing::memoised_optimum;
double optimum(const Problem& problem) { return memoised_optimum(problem); }

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
    testing::ChainReferenceSolver reference(problem);
    const double expected = reference.value_of([&](const testing::ChainReferenceSolver::Node& node) {
      return (node.time + reference.joint(node)) % problem.skeleton_count();
    });
    EXPECT_NEAR(exact.expected_reward, expected, 1e-12) << "seed " << seed;
    EXPECT_LE(exact.expected_reward, optimum(problem) + 1e-12) << "seed " << seed;
  }
}

// The layered solver walks the MDP's own outcomes in the memoised solver's order, layer by
// layer, with the chains' joint state and the timed slots in its keys: the same value to the
// bit, the same first choice and states, on any thread count; the policy it keeps holds the
// chains' state (its states solve to its values).
TEST(Chains, TheLayeredSolverEqualsTheMemoisedOneBitForBit) {
  const int count = testing::repetitions_to_check(60);
  int valued = 0;
  int large = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Problem problem =
        testing::with_random_chains(testing::random_instance(seed + 900, 4, 4, 14), seed + 900, seed % 2 == 0);
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    valued += solver.solve(mdp.start()) > 0 ? 1 : 0;
    large += solver.states() >= 20 ? 1 : 0;
    testing::expect_layered_equals_memoised(mdp);
  }
  EXPECT_GT(valued, count / 3);  // not a comparison of zeros
  EXPECT_GT(large, count / 6);   // nor of one-state trees only
}

// The coffee building has 632,272 states (5 s here for the three solvers): the sanitizer run,
// which checks a share of the repetitions, takes the meeting only.
TEST(Chains, TheLayeredSolverAndTheSearchEqualTheMemoisedOneOnTheShippedExamples) {
  const std::vector<std::string> paths{"data/instances/chains/meeting-through-the-queue.json",
                                       "data/instances/chains/coffee-building.json"};
  const int count = testing::repetitions_to_check(static_cast<int>(paths.size()));
  for (int i = 0; i < count; ++i) {
    const std::string& path = paths[static_cast<std::size_t>(i)];
    SCOPED_TRACE(path);
    const Problem problem = load_problem(testing::source_path(path));
    ASSERT_TRUE(problem.has_chains());
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    const double optimum = solver.solve(mdp.start());
    EXPECT_GT(optimum, 0.4);
    LayeredSolveOptions options;
    options.threads = 2;
    const LayeredSolution layered = solve_layered(mdp, options);
    ASSERT_TRUE(layered.exact);
    EXPECT_EQ(layered.lower, optimum);
    EXPECT_EQ(layered.first_choice, solver.best_choice(mdp.start()).value_or(-1));
    EXPECT_EQ(layered.states, solver.states());
    const SearchSolution search = solve_search(mdp);
    ASSERT_TRUE(search.exact);
    EXPECT_EQ(search.lower, optimum);
    EXPECT_EQ(search.first_choice, layered.first_choice);
  }
}

// A cap ends the forward pass at a frontier valued by ValueBounds (0 below, the clairvoyant
// relaxation above with chains): the interval holds the optimum at every cap, and the caps do cut.
TEST(Chains, EveryLayeredCapsIntervalHoldsTheOptimum) {
  const int count = testing::repetitions_to_check(40);
  int cut = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const Problem problem =
        testing::with_random_chains(testing::random_instance(seed + 300, 4, 4, 10), seed + 300, seed % 2 == 1);
    const double expected = optimum(problem);
    const Mdp mdp(problem);
    for (const std::uint64_t cap : {std::uint64_t{3}, std::uint64_t{10}, std::uint64_t{30}}) {
      LayeredSolveOptions options;
      options.max_states = cap;
      const LayeredSolution layered = solve_layered(mdp, options);
      EXPECT_LE(layered.lower, expected + 1e-12) << seed << " cap " << cap;
      EXPECT_GE(layered.upper, expected - 1e-12) << seed << " cap " << cap;
      cut += layered.exact ? 0 : 1;
    }
  }
  EXPECT_GT(cut, count);
}

// The search takes the memoised solver's keys and outcomes with chains, and ValueBounds holds
// there (0 below, the relaxation above): the same value to the bit and the same first choice,
// after trials too; a cap's interval holds the optimum.
TEST(Chains, TheSearchEqualsTheMemoisedSolverBitForBit) {
  const int count = testing::repetitions_to_check(60);
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Problem problem =
        testing::with_random_chains(testing::random_instance(seed + 900, 4, 4, 14), seed + 900, seed % 2 == 0);
    testing::expect_search_equals_memoised(Mdp(problem));
  }
}

TEST(Chains, TheLayeredSolverRefusesWhatBoundsOnlyASuccessProbability) {
  const Problem problem = testing::queue_wait_instance("");  // (an Mdp holds a reference to its problem)
  testing::expect_layered_refuses_a_tolerance_and_a_split(Mdp(problem));
}

TEST(Chains, EveryAllocatorTakesThem) {
  const Problem problem = testing::queue_wait_instance("");
  const Mdp mdp(problem);
  const AllocatorRegistry& registry = allocator_registry();
  EXPECT_EQ(registry.names({}, {Capability::chains}), std::vector<std::string>{});
  for (const std::string& name : registry.names({}, {Capability::needs_policy})) {
    EXPECT_NO_THROW(registry.make_factory(name, mdp, {})) << name;
  }
}

}  // namespace
}  // namespace ontime
