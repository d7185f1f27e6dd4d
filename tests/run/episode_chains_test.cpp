// Exogenous chains and expiry (SPEC §9) in episodes: the session simulates the chains from the
// episode's seed and executes the completed plan in them; the mean reward and the success rate
// estimate the exact values, the same for every thread count.
#include <gtest/gtest.h>

#include <string>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/session.hpp"
#include "ontime/util/error.hpp"

namespace ontime {
namespace {

// To the meeting through the coffee queue (worth 1) or straight (0.7, falling with the finish);
// the queue's length sets the wait, and the meeting room's door may lock for good.
Problem coffee() {
  return parse_problem(R"({"deadline": 12,
      "chains": {"queue": {"states": ["short", "long"], "start": "short", "transitions": [[0.7, 0.3], [0.4, 0.6]]},
                 "door": {"states": ["open", "locked"], "start": "open", "transitions": [[0.95, 0.05], [0, 1]]}},
      "actions": {
        "go": {"planning": {"pmf": {"1": 0.6, "2": 0.4}}, "execution": {"pmf": {"2": 1.0}}},
        "wait": {"planning": {"pmf": {"1": 0.8}},
                 "execution": {"chain": "queue", "by_state": {"short": {"pmf": {"1": 1.0}}, "long": {"pmf": {"4": 0.5, "6": 0.5}}}}},
        "enter": {"planning": {"pmf": {"2": 0.7, "3": 0.3}}, "execution": {"pmf": {"1": 1.0}},
                  "expires": {"after": 11, "chain": "door", "states": ["locked"]}},
        "walk": {"planning": {"pmf": {"2": 0.5, "4": 0.5}}, "execution": {"pmf": {"3": 1.0}},
                 "expires": {"chain": "door", "states": ["locked"]}}},
      "skeletons": [["go", "wait", "enter"], ["walk"]],
      "rewards": [1.0, {"value": 0.7, "per_step": 0.02}]})",
                       "coffee.json");
}

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

TEST(EpisodeChains, WhatSessionsDoNotTakeYetIsRefused) {
  const Problem problem = coffee();
  Session session(problem, Session::AllocatorMaker{}, 1);
  EXPECT_THROW(session.retire_skeleton(0), UsageError);
  EXPECT_EQ(session.problem().skeleton_count(), 2);  // nothing lost
}

}  // namespace
}  // namespace ontime
