// Rewards beyond success (SPEC §8) in episodes: each episode's reward, their mean against the exact
// expected reward, and the same figures for every thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/session.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

// Instance 3 with a reward per skeleton, one of them falling with the finish time.
Problem rewarded_instance3() {
  const Problem problem = testing::paper_instance("instance3");
  std::vector<SkeletonReward> rewards(static_cast<std::size_t>(problem.skeleton_count()), {0.6, 0.0});
  rewards[0] = {1.0, 0.02};
  return problem.with_rewards(rewards);
}

TEST(EpisodeRewards, TheMeanRewardEstimatesTheExactExpectedRewardForEveryThreadCount) {
  const Problem problem = rewarded_instance3();
  const Mdp mdp(problem);
  const AllocatorFactory factory = make_allocator_factory("optimal", mdp);
  MonteCarloOptions options;
  options.episodes = 20'000;
  options.seed = 5;
  options.threads = 1;
  std::vector<double> rewards(options.episodes, -1.0);
  options.on_episode = [&rewards, &problem](std::uint64_t episode, const EpisodeResult& result) {
    // Each episode's reward: its solution's reward at some finish, 0 on failure.
    if (result.status == Status::success) {
      EXPECT_GT(result.reward, 0.0);
      EXPECT_LE(result.reward, problem.reward(result.solution).value);
    } else {
      EXPECT_EQ(result.reward, 0.0);
    }
    rewards[episode] = result.reward;
  };
  const MonteCarloResult one = run_monte_carlo(mdp, factory, options);
  double sum = 0;
  for (const double reward : rewards) sum += reward;
  EXPECT_NEAR(one.mean_reward, sum / 20'000.0, 1e-9);
  EXPECT_LT(one.mean_reward, one.success_rate);  // every reward is below 1
  const double exact = OptimalSolver(mdp).solve(mdp.start());
  EXPECT_NEAR(one.mean_reward, exact, 4 * one.reward_ci95);
  EXPECT_GT(one.reward_ci95, 0.0);
  options.on_episode = {};
  options.threads = 2;
  const MonteCarloResult two = run_monte_carlo(mdp, factory, options);
  EXPECT_EQ(two.mean_reward, one.mean_reward);
  EXPECT_EQ(two.reward_ci95, one.reward_ci95);
}

TEST(EpisodeRewards, WithoutRewardsTheMeanRewardIsTheSuccessRate) {
  const Problem problem = testing::paper_instance("instance2");
  const Mdp mdp(problem);
  MonteCarloOptions options;
  options.episodes = 3'000;
  const MonteCarloResult result = run_monte_carlo(mdp, make_allocator_factory("dp-rerun", mdp), options);
  EXPECT_EQ(result.mean_reward, result.success_rate);
  EXPECT_NEAR(result.reward_ci95, result.ci95, 1e-12);
}

TEST(EpisodeRewards, SkeletonsThatArriveOrLeaveKeepTheirRewards) {
  const Problem base = rewarded_instance3();
  const int count = base.skeleton_count();
  Session session(base, Session::AllocatorMaker{}, 1);
  session.retire_skeleton(0);
  ASSERT_EQ(session.problem().skeleton_count(), count - 1);
  for (int k = 0; k + 1 < count; ++k) EXPECT_EQ(session.problem().reward(k), base.reward(k + 1)) << k;
  const std::vector<std::string> first{base.action(base.action_at(0, 0)).id};
  const int added = session.add_skeleton(first, {}, {0.9, 0.01});
  EXPECT_EQ(session.problem().reward(added), (SkeletonReward{0.9, 0.01}));
  EXPECT_EQ(session.problem().reward(0), base.reward(1));
  // The new one-action skeleton, refined in 8 steps and executed in 5: worth its reward at 13.
  for (int step = 0; step < 7; ++step) {
    session.decide(added);
    ASSERT_EQ(session.report(Observation::not_yet()), Status::running);
  }
  session.decide(added);
  ASSERT_EQ(session.report_refined(5), Status::success);
  EXPECT_EQ(session.solution(), added);
  EXPECT_DOUBLE_EQ(session.reward(), 0.9 - 0.01 * 13);
}

}  // namespace
}  // namespace ontime
