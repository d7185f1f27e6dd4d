// Episodes in which the robot acts while planning (SPEC §10): the session's checks and steps, the
// episode runner's Monte Carlo against the exact values of the same allocators, and seeding.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/concurrent_session.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/util/error.hpp"
#include "support/chain_reference.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

Problem two_moves() {
  // a is found in 1 step and runs 2; b is found after 2 more steps and runs 1; deadline 5.
  // Plan first: refined at 3, executed by 6, too late. Acting while planning: a runs over steps
  // 1-3 while b is planned, b over 3-4.
  return parse_problem(R"({"deadline": 5, "acting": "concurrent",
    "actions": {"a": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"2": 1}}},
                "b": {"planning": {"pmf": {"2": 1}}, "execution": {"pmf": {"1": 1}}}},
    "skeletons": [["a", "b"]]})",
                       "two-moves");
}

TEST(ConcurrentSession, TheCallersMovesAndReportsWalkTheModel) {
  const ConcurrentMdp mdp(two_moves());
  ConcurrentSession session(mdp);
  ConcurrentDecision decision = session.decide({-1, 0});
  EXPECT_EQ(decision.action, 0);
  EXPECT_EQ(session.report_refined(2), Status::running);
  decision = session.decide({0, ConcurrentMdp::kWait});  // starts a at 1: no time passes
  EXPECT_TRUE(decision.is_start());
  EXPECT_EQ(session.steps_used(), 1);
  EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 2);
  EXPECT_EQ(session.decide({-1, 0}).action, 1);
  EXPECT_EQ(session.report_not_yet(), Status::running);
  session.decide({-1, 0});
  EXPECT_EQ(session.report_refined(1), Status::running);
  EXPECT_EQ(session.steps_used(), 3);
  EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 0);
  session.decide({1, ConcurrentMdp::kWait});  // b, the last action: done at 4
  EXPECT_EQ(session.status(), Status::success);
  EXPECT_EQ(session.solution(), 0);
  EXPECT_EQ(session.finish(), 4);
  EXPECT_EQ(session.reward(), 1.0);
  EXPECT_EQ(session.started(), (std::vector<int>{0, 1}));
  EXPECT_EQ(session.attempts()[1].effort, 2);
  EXPECT_TRUE(session.attempts()[1].found);
}

TEST(ConcurrentSession, MovesAndReportsTheStateDoesNotAllowAreRefused) {
  const ConcurrentMdp mdp(two_moves());
  ConcurrentSession session(mdp);
  EXPECT_THROW(session.choose(), std::logic_error);                     // no allocator
  EXPECT_THROW(session.report_not_yet(), std::logic_error);             // nothing decided
  EXPECT_THROW(session.decide({0, ConcurrentMdp::kWait}), UsageError);  // a is not refined
  EXPECT_THROW(session.decide({-1, 1}), UsageError);                    // no skeleton 1
  session.decide({-1, 0});
  EXPECT_THROW(session.decide({-1, 0}), std::logic_error);                // awaiting the report
  EXPECT_THROW(session.report_refined(-1), UsageError);                   // a negative execution
  EXPECT_THROW(session.report(Observation::backtracked(0)), UsageError);  // not modelled here
  EXPECT_EQ(session.report_refined(2), Status::running);                  // the session is unchanged
  session.decide({-1, ConcurrentMdp::kWait});
  EXPECT_THROW(session.report_refined(1), UsageError);  // the planner idled
  const auto allocator = make_concurrent_allocator_factory("dp-rerun", mdp)();
  ConcurrentSession driven(mdp, *allocator);
  EXPECT_THROW(driven.decide({-1, 0}), std::logic_error);  // its allocator decides
}

TEST(ConcurrentSession, ARobotThatFinishesEarlyStartsTheNextActionSooner) {
  // a is found at 1 and would run to 3; the robot reports it done at 2, while b is still planned.
  // b is found at 3 either way and then runs 3 -> 4; reported at 2, nothing is left of a.
  const ConcurrentMdp mdp(two_moves());
  ConcurrentSession session(mdp);
  session.decide({-1, 0});
  session.report_refined(2);
  EXPECT_THROW(session.report_execution_finished(0), UsageError);  // not started yet
  session.decide({0, ConcurrentMdp::kWait});
  session.decide({-1, 0});
  EXPECT_THROW(session.report_execution_finished(0), std::logic_error);  // a step awaits its report
  session.report_not_yet();
  EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 1);
  EXPECT_EQ(session.report_execution_finished(0), Status::running);
  EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 0);
  EXPECT_EQ(session.report_execution_finished(0), Status::running);  // told twice: nothing more
  try {
    session.report_execution_finished(1);
    ADD_FAILURE() << "an execution never started was accepted";
  } catch (const UsageError& error) {
    EXPECT_NE(std::string(error.what()).find("was never started"), std::string::npos) << error.what();
  }
  session.decide({-1, 0});
  session.report_refined(1);
  session.decide({1, ConcurrentMdp::kWait});
  EXPECT_EQ(session.status(), Status::success);
  EXPECT_EQ(session.finish(), 4);
}

TEST(ConcurrentSession, ATooSlowPlanFailsWhenTheRobotWouldFinishLate) {
  // Found with an execution too slow to finish by the deadline: nothing can finish any more.
  const ConcurrentMdp mdp(two_moves());
  ConcurrentSession session(mdp);
  session.decide({-1, 0});
  EXPECT_EQ(session.report_refined(kNever), Status::failure);
  EXPECT_EQ(session.reward(), 0.0);
  EXPECT_EQ(session.solution(), -1);
  EXPECT_THROW(session.decide({-1, 0}), std::logic_error);
}

double half_width_of(double value, std::uint64_t episodes) {
  return std::sqrt(std::max(value * (1 - value), 0.0) / static_cast<double>(episodes));
}

// Allocator `name`'s exact value in `mdp` (the solver's policy mode) and `episodes` of its
// episodes in the runner's hidden worlds (seed `seed`, 2 threads).
std::pair<ExactEvaluation, MonteCarloResult> exact_and_sampled(const ConcurrentMdp& mdp, const std::string& name,
                                                               std::uint64_t episodes, std::uint64_t seed) {
  const ConcurrentAllocatorFactory factory = make_concurrent_allocator_factory(name, mdp);
  const auto allocator = factory();
  MonteCarloOptions options;
  options.episodes = episodes;
  options.seed = seed;
  options.threads = 2;
  return {evaluate_exactly(mdp, *allocator), run_monte_carlo(mdp, factory, options)};
}

TEST(ConcurrentEpisodes, TheirMeanRewardIsTheExactValue) {
  // The runner's hidden worlds against ConcurrentSolver's policy mode, for allocators of each
  // kind of commit rule (the optimum's, dp-rerun's own, the eager rule), with and without rewards.
  const auto episodes = static_cast<std::uint64_t>(testing::repetitions_to_check(20'000));
  for (const Problem& base : {testing::paper_instance("instance2"), testing::navigation_with_deadline(14),
                              testing::with_random_rewards(testing::paper_instance("instance3"), 5)}) {
    const Problem problem = base.with_acting(Acting::concurrent);
    const ConcurrentMdp mdp(problem);
    for (const std::string name : {"optimal", "dp-rerun", "greedy", "round-robin"}) {
      const auto [exact, sampled] = exact_and_sampled(mdp, name, episodes, 11);
      // Rewards lie in [0, 1], so their variance is at most the mean's v(1 - v).
      EXPECT_NEAR(sampled.mean_reward, exact.expected_reward,
                  4 * half_width_of(exact.expected_reward, episodes) + 1e-12)
          << problem.name() << " " << name;
      EXPECT_NEAR(sampled.success_rate, exact.success_probability,
                  4 * half_width_of(exact.success_probability, episodes) + 1e-12)
          << problem.name() << " " << name;
    }
  }
}

TEST(ConcurrentEpisodes, WithBacktrackingTheirSuccessIsTheExactValue) {
  // The hidden worlds draw every attempt's end, give-ups and culprits included (SPEC §7), and
  // start new attempts below a culprit as the model discards them (SPEC §10).
  const auto episodes = static_cast<std::uint64_t>(testing::repetitions_to_check(20'000));
  for (const std::uint64_t seed : {4U, 9U}) {
    const Problem problem =
        testing::with_backtracking(testing::random_instance(seed + 40, 4, 3, 10), seed).with_acting(Acting::concurrent);
    ASSERT_TRUE(problem.has_backtracking());
    const ConcurrentMdp mdp(problem);
    for (const std::string name : {"optimal", "greedy", "round-robin"}) {
      const auto [exact, sampled] = exact_and_sampled(mdp, name, episodes, 13);
      EXPECT_NEAR(sampled.success_rate, exact.success_probability,
                  4 * half_width_of(exact.success_probability, episodes) + 1e-12)
          << "seed " << seed << " " << name;
      // Neither sure nor hopeless, so that the comparison can tell.
      EXPECT_GT(exact.success_probability, 0.05) << "seed " << seed << " " << name;
      EXPECT_LT(exact.success_probability, 0.95) << "seed " << seed << " " << name;
    }
  }
}

TEST(ConcurrentEpisodes, TheSameSeedGivesTheSameEpisodesOnAnyThreadCount) {
  // The randomised kinds (thompson, mcts) and the searches, which keep state within an episode.
  const ConcurrentMdp navigation(testing::navigation_with_deadline(16).with_acting(Acting::concurrent));
  const ConcurrentMdp third(testing::paper_instance("instance3").with_acting(Acting::concurrent));
  struct Case {
    const ConcurrentMdp* mdp;
    std::string name;
    ParameterValues values;
    std::uint64_t episodes;
  };
  const std::vector<Case> cases = {{&navigation, "dp-rerun", {}, 2'000},
                                   {&navigation, "thompson", {}, 2'000},
                                   {&third, "mcts", {{"iterations", "300"}}, 200},
                                   {&third, "branch-and-bound", {{"iterations", "300"}}, 200}};
  for (const Case& run : cases) {
    const ConcurrentAllocatorFactory factory = make_concurrent_allocator_factory(run.name, *run.mdp, run.values);
    MonteCarloOptions options;
    options.episodes = run.episodes;
    options.seed = 3;
    options.threads = 1;
    const MonteCarloResult one = run_monte_carlo(*run.mdp, factory, options);
    options.threads = 2;
    const MonteCarloResult two = run_monte_carlo(*run.mdp, factory, options);
    EXPECT_EQ(one.successes, two.successes) << run.name;
    EXPECT_EQ(one.mean_reward, two.mean_reward) << run.name;
    EXPECT_GT(one.successes, 0U) << run.name;
  }
}

TEST(ConcurrentEpisodes, AThompsonAllocatorIsNotValuedExactly) {
  const ConcurrentMdp mdp(testing::paper_instance("instance1").with_acting(Acting::concurrent));
  const auto allocator = make_concurrent_allocator_factory("thompson", mdp)();
  EXPECT_FALSE(allocator->is_stationary());
  EXPECT_THROW((void)evaluate_exactly(mdp, *allocator), UsageError);
}

// Exogenous chains and expiry (SPEC §9) acting while planning: the session moves the simulated
// chains one step per step and draws a chain-dependent execution from the chain's state when the
// action starts; an action starts only while the MDP says it may.

Problem chain_instance(const std::string& name) {
  return load_problem(testing::source_path("data/instances/chains/" + name + ".json")).with_acting(Acting::concurrent);
}

// Allocator `name`'s episodes against its exact value (4 standard errors of the reward, which
// lies in [0, 1]); for optimal the exact value is also ConcurrentSolver's optimum V*.
void expect_episodes_at_the_exact_value(const Problem& problem, const std::string& name, std::uint64_t episodes,
                                        const std::string& label) {
  const ConcurrentMdp mdp(problem);
  const auto [exact, sampled] = exact_and_sampled(mdp, name, episodes, 17);
  EXPECT_NEAR(sampled.mean_reward, exact.expected_reward, 4 * half_width_of(exact.expected_reward, episodes) + 1e-12)
      << label << " " << name;
  EXPECT_NEAR(sampled.success_rate, exact.success_probability,
              4 * half_width_of(exact.success_probability, episodes) + 1e-12)
      << label << " " << name;
  if (name == "optimal") {
    ConcurrentSolver solver(mdp);
    EXPECT_NEAR(exact.expected_reward, solver.solve(mdp.start()), 1e-12) << label;
  }
}

TEST(ConcurrentEpisodesWithChains, TheirRewardIsTheExactValueOnTheChainInstances) {
  // The cup through a door that locks at random (with give-ups, SPEC §7) and the meeting through
  // the coffee queue (an execution drawn from the queue's state when it starts; a door that locks
  // for good), for the optimum's commit rule and the eager one.
  const auto episodes = static_cast<std::uint64_t>(testing::repetitions_to_check(20'000));
  for (const std::string instance : {"cup-through-the-door", "meeting-through-the-queue"}) {
    const Problem problem = chain_instance(instance);
    ASSERT_TRUE(problem.is_timed());
    for (const std::string name : {"optimal", "greedy", "round-robin"}) {
      expect_episodes_at_the_exact_value(problem, name, episodes, instance);
    }
  }
}

TEST(ConcurrentEpisodesWithChains, TheirRewardIsTheExactValueOnRandomInstances) {
  // Random chains, chain-dependent executions and expiry (half with rewards, one with give-ups).
  const auto episodes = static_cast<std::uint64_t>(testing::repetitions_to_check(10'000));
  for (const std::uint64_t seed : {2U, 3U, 6U}) {
    Problem problem = testing::with_random_chains(testing::random_instance(seed + 5000, 4, 3, 10), seed, seed % 2 == 0);
    if (seed % 3 == 0) problem = testing::with_backtracking(problem, seed);
    problem = problem.with_acting(Acting::concurrent);
    ASSERT_TRUE(problem.is_timed());
    for (const std::string name : {"optimal", "greedy", "round-robin"}) {
      expect_episodes_at_the_exact_value(problem, name, episodes, "seed " + std::to_string(seed));
    }
  }
}

TEST(ConcurrentEpisodesWithChains, TheRobotWaitsForTheDoorInItsEpisodes) {
  // go then through, each found in 1 step and run in 1; through cannot start while the door is
  // locked, locked at 0 and opening with probability 1/2 per step for good; deadline 6. The
  // optimum waits at the door and starts through at the first open step up to 5: 1 - 1/32.
  const Problem problem = testing::door_opening_at_random().with_acting(Acting::concurrent);
  const ConcurrentMdp mdp(problem);
  const auto episodes = static_cast<std::uint64_t>(testing::repetitions_to_check(20'000));
  for (const std::string name : {"optimal", "greedy"}) {
    const auto [exact, sampled] = exact_and_sampled(mdp, name, episodes, 5);
    EXPECT_NEAR(exact.success_probability, 1.0 - 1.0 / 32, 1e-15) << name;
    EXPECT_NEAR(sampled.success_rate, 1.0 - 1.0 / 32, 4 * half_width_of(1.0 - 1.0 / 32, episodes)) << name;
  }
}

TEST(ConcurrentEpisodesWithChains, TheSameSeedGivesTheSameEpisodesOnAnyThreadCount) {
  const ConcurrentMdp mdp(chain_instance("meeting-through-the-queue"));
  for (const std::string name : {"optimal", "greedy", "thompson"}) {
    const ConcurrentAllocatorFactory factory = make_concurrent_allocator_factory(name, mdp);
    MonteCarloOptions options;
    options.episodes = 2'000;
    options.seed = 3;
    options.threads = 1;
    const MonteCarloResult one = run_monte_carlo(mdp, factory, options);
    options.threads = 2;
    const MonteCarloResult two = run_monte_carlo(mdp, factory, options);
    EXPECT_EQ(one.successes, two.successes) << name;
    EXPECT_EQ(one.mean_reward, two.mean_reward) << name;
    EXPECT_GT(one.successes, 0U) << name;
    EXPECT_LT(one.successes, options.episodes) << name;
  }
}

TEST(ConcurrentEpisodesWithChains, AStartTheChainsBlockIsRefused) {
  // The door is locked for good: through, once refined, may never start.
  const Problem problem = parse_problem(R"({"deadline": 6, "acting": "concurrent",
    "chains": {"door": {"states": ["open", "locked"], "start": "locked", "transitions": [[1, 0], [0, 1]]}},
    "actions": {"go": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"0": 1}}},
                "through": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"1": 1}},
                            "expires": {"chain": "door", "states": ["locked"]}}},
    "skeletons": [["go", "through"]]})",
                                        "locked");
  const ConcurrentMdp mdp(problem);
  ConcurrentSession session(mdp, 4);
  session.decide({-1, 0});
  EXPECT_EQ(session.report_refined(0), Status::running);
  session.decide({0, ConcurrentMdp::kWait});  // go: no time
  session.decide({-1, 0});
  EXPECT_EQ(session.report_refined(1), Status::running);
  EXPECT_THROW(session.decide({1, ConcurrentMdp::kWait}), UsageError);
  EXPECT_EQ(session.started(), std::vector<int>{0});
  EXPECT_EQ(session.status(), Status::running);
}

}  // namespace
}  // namespace ontime
