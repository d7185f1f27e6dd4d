// Exogenous chains and expiry (SPEC §9) in episodes: the session simulates the chains from the
// episode's seed and executes the completed plan in them; the mean reward and the success rate
// estimate the exact values, the same for every thread count.
#include <gtest/gtest.h>

#include <string>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

// To the meeting through the coffee queue or straight there; the door may lock (the example
// instance of SPEC §9).
Problem coffee() { return load_problem(testing::source_path("data/instances/chains/meeting-through-the-queue.json")); }

TEST(EpisodeChains, EpisodesEstimateTheExactValuesForEveryThreadCount) {
  const Problem problem = coffee();
  const Mdp mdp(problem);
  for (const std::string name : {"optimal", "round-robin"}) {
    const AllocatorFactory factory = make_allocator_factory(name, mdp);
    const ExactEvaluation exact = evaluate_exactly(mdp, *factory());
    ASSERT_GT(exact.expected_reward, 0.1) << name;
    ASSERT_LT(exact.success_probability, 0.99) << name;  // some plans fail in their execution
    MonteCarloOptions options;
    options.episodes = 20'000;
    options.seed = 3;
    options.threads = 1;
    const MonteCarloResult one = run_monte_carlo(mdp, factory, options);
    EXPECT_NEAR(one.mean_reward, exact.expected_reward, 4 * one.reward_ci95) << name;
    EXPECT_NEAR(one.success_rate, exact.success_probability, 4 * one.ci95) << name;
    options.threads = 2;
    const MonteCarloResult two = run_monte_carlo(mdp, factory, options);
    EXPECT_EQ(two.mean_reward, one.mean_reward) << name;
    EXPECT_EQ(two.successes, one.successes) << name;
  }
}

TEST(EpisodeChains, ASessionWithChainsRetiresASkeleton) {
  const Problem problem = coffee();
  Session session(problem, Session::AllocatorMaker{}, 1);
  session.retire_skeleton(0);
  EXPECT_EQ(session.problem().skeleton_count(), 1);
  EXPECT_EQ(session.state().chains, Mdp(problem).start().chains);
}

}  // namespace
}  // namespace ontime
