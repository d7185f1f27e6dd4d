#include "ontime/allocators/optimal.hpp"

#include <gtest/gtest.h>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"
#include "support/reference_solver.hpp"

namespace ontime {
namespace {

TEST(Optimal, FigureOneOptimumIsPointFiveSixTwoFive) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  OptimalSolver solver(mdp);
  EXPECT_DOUBLE_EQ(solver.solve(mdp.start()), 0.5625);
  // The paper's optimal policy first refines the shared action d1 (sigma1 and sigma2 share it).
  EXPECT_EQ(solver.best_choice(mdp.start()), 0);
  // After d1 fails its first step, the only hope is d3 (sigma3).
  State missed = mdp.start();
  mdp.apply(missed, 0, Observation::not_yet());
  EXPECT_DOUBLE_EQ(solver.solve(missed), 0.5);
  EXPECT_EQ(solver.best_choice(missed), 2);
  // After d1 is refined with a fast execution, d12 then d22: 0.5 + 0.25.
  State refined = mdp.start();
  mdp.apply(refined, 0, Observation::found(1));
  EXPECT_DOUBLE_EQ(solver.solve(refined), 0.75);
  EXPECT_EQ(solver.best_choice(refined), 0);
}

TEST(Optimal, MatchesAnIndependentReferenceOnThePaperInstances) {
  for (const char* name : {"figure1", "instance2", "instance4", "instance5"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    EXPECT_NEAR(solver.solve(mdp.start()), testing::ReferenceSolver(problem).optimum(), 1e-12) << name;
  }
}

TEST(Optimal, MatchesAnIndependentReferenceOnRandomInstances) {
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    const Problem problem = testing::random_instance(seed, 4, 3, 8);
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    EXPECT_NEAR(solver.solve(mdp.start()), testing::ReferenceSolver(problem).optimum(), 1e-12) << "seed " << seed;
  }
}

// States are memoised under 16-byte, 32-byte or full keys depending on the skeleton count and
// the deadline; each encoding must give the reference value.
TEST(Optimal, EveryStateEncodingGivesTheReferenceValue) {
  const int count = testing::repetitions_to_check(60);
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count);
       ++seed) {  // up to 6 skeletons: 16- and 32-byte keys
    const Problem problem = testing::random_instance(seed * 7919, 6, 2, 7);
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    EXPECT_NEAR(solver.solve(mdp.start()), testing::ReferenceSolver(problem).optimum(), 1e-12) << "seed " << seed;
  }
  // A deadline above 253 needs full keys. Three single-action skeletons, each found with
  // probability 1/2 at a fixed step (100, 100, 50) and executed at once: all three fit in
  // D = 254 one after the other, so the optimum is 1 - 1/8; with D = 249 only two fit: 3/4.
  const auto at = [](std::size_t step) {
    std::vector<double> pmf(step + 1, 0.0);
    pmf[step] = 0.5;
    return Distribution::from_pmf(pmf);
  };
  for (const auto& [deadline, expected] : {std::pair{254, 0.875}, std::pair{249, 0.75}}) {
    const Problem problem(
        "long", deadline, 1.0,
        {Action{"a", at(100), Distribution::from_pmf({1.0})}, Action{"b", at(100), Distribution::from_pmf({1.0})},
         Action{"c", at(50), Distribution::from_pmf({1.0})}},
        {{0}, {1}, {2}});
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    EXPECT_NEAR(solver.solve(mdp.start()), expected, 1e-12) << deadline;
    OptimalAllocator allocator(mdp);
    EXPECT_NEAR(evaluate_exactly(mdp, allocator).success_probability, expected, 1e-12) << deadline;
  }
}

TEST(Optimal, FollowingItsChoicesAchievesItsValue) {
  for (const char* name : {"figure1", "instance1", "instance2", "instance3", "instance4", "instance5"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    OptimalAllocator allocator(mdp);
    const double optimum = OptimalSolver(mdp).solve(mdp.start());
    EXPECT_NEAR(evaluate_exactly(mdp, allocator).success_probability, optimum, 1e-12) << name;
  }
}

TEST(Optimal, IsAtLeastEveryOtherAllocator) {
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const Problem problem = testing::random_instance(seed, 4, 3, 10);
    const Mdp mdp(problem);
    const double optimum = OptimalSolver(mdp).solve(mdp.start());
    // Every stationary kind that needs nothing beyond the instance (mcts and ppo have their own tests).
    for (const std::string& name : allocator_registry().names({Capability::stationary}, {Capability::needs_policy})) {
      const auto allocator = make_allocator_factory(name, mdp)();
      const double value = evaluate_exactly(mdp, *allocator).success_probability;
      EXPECT_LE(value, optimum + 1e-12) << name << " seed " << seed;
    }
  }
}

TEST(Optimal, StopsAtTheStateCapWithAClearError) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  OptimalSolver solver(mdp, 50);
  try {
    solver.solve(mdp.start());
    FAIL() << "expected ResourceLimitError";
  } catch (const ResourceLimitError& error) {
    EXPECT_NE(std::string(error.what()).find("cap of 50 states"), std::string::npos) << error.what();
    // The library names its parameter, not a command-line flag.
    EXPECT_NE(std::string(error.what()).find("(the max-states parameter)"), std::string::npos) << error.what();
    EXPECT_EQ(std::string(error.what()).find("--"), std::string::npos) << error.what();
  }
  EXPECT_LE(solver.states(), 50U);
  EXPECT_THROW(make_allocator_factory("optimal", mdp, {{"max-states", "50"}}), ResourceLimitError);
}

TEST(Optimal, TiesGoToTheLowestIndex) {
  // Two identical independent skeletons: either is optimal; the first must be chosen.
  const Action twin_a{"a", Distribution::from_pmf({0.0, 0.5, 0.5}), Distribution::from_pmf({0.0, 1.0})};
  const Action twin_b{"b", twin_a.planning, twin_a.execution};
  const Problem problem("twins", 4, 1.0, {twin_a, twin_b}, {{0}, {1}});
  const Mdp mdp(problem);
  OptimalSolver solver(mdp);
  solver.solve(mdp.start());
  EXPECT_EQ(solver.best_choice(mdp.start()), 0);
}

}  // namespace
}  // namespace ontime
