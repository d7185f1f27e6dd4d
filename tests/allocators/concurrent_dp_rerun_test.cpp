// dp-rerun when the robot acts while planning (SPEC §10): Eq. (1) with the robot's backlog, the
// eager commit rule, and its exact value by the solver's policy mode, against the optimum and
// against episodes drawn from the model.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "ontime/allocators/dp_rerun.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

struct Figures {
  double policy;
  double optimum;
};

// The policy's exact value, by the solver's policy mode.
double policy_value(const Problem& problem) {
  const ConcurrentMdp mdp(problem);
  ConcurrentDpRerunAllocator policy(mdp);
  ConcurrentSolver evaluation(mdp, [&](const ConcurrentState& state) { return policy.choose(state); });
  return evaluation.solve(mdp.start());
}

Figures figures(const Problem& problem) {
  const ConcurrentMdp mdp(problem);
  ConcurrentSolver optimal(mdp);
  return {policy_value(problem), optimal.solve(mdp.start())};
}

// The mean reward of `episodes` episodes of the policy, each drawn from the model's outcomes.
double sampled_value(const Problem& problem, std::uint64_t episodes, std::uint64_t seed) {
  const ConcurrentMdp mdp(problem);
  ConcurrentDpRerunAllocator policy(mdp);
  SplitMix64 generator(seed);
  double total = 0;
  std::vector<std::pair<double, ConcurrentState>> outcomes;
  for (std::uint64_t episode = 0; episode < episodes; ++episode) {
    ConcurrentState state = mdp.start();
    while (mdp.any_live(state)) {
      const ConcurrentMdp::Move move = policy.choose(state);
      if (move.is_start()) {
        ConcurrentMdp::StartOutcome started = mdp.start_action(state, move.start);
        if (started.ends) {
          total += started.reward;
          break;
        }
        state = std::move(started.next);
        continue;
      }
      if (ConcurrentMdp::time(state) >= mdp.deadline()) break;
      outcomes.clear();
      mdp.for_each_step_outcome(state, move.refine, [&](double probability, const ConcurrentState& next) {
        outcomes.emplace_back(probability, next);
      });
      state = outcomes[sample_index(
                           outcomes.size(), [&](std::size_t i) { return outcomes[i].first; }, generator)]
                  .second;
    }
  }
  return total / static_cast<double>(episodes);
}

TEST(ConcurrentDpRerun, ComesCloseToTheOptimumOnThePaperInstancesAndNavigation) {
  // Instance 2 is dp-rerun's own shortfall: 0.69 against 0.72, plan-first as here (Table I).
  for (const std::string name : {"instance1", "instance3", "instance4", "instance5"}) {
    const Figures got = figures(testing::paper_instance(name));
    EXPECT_LE(got.policy, got.optimum + 1e-12) << name;
    EXPECT_GE(got.policy, 0.98 * got.optimum) << name;
  }
  const Figures second = figures(testing::paper_instance("instance2"));
  EXPECT_NEAR(second.policy, 0.69, 1e-12);
  EXPECT_NEAR(second.optimum, 0.72, 1e-12);
  const Figures navigation = figures(testing::navigation_with_deadline(14));
  EXPECT_LE(navigation.policy, navigation.optimum + 1e-12);
  EXPECT_GE(navigation.policy, 0.98 * navigation.optimum);
}

TEST(ConcurrentDpRerun, ItsExactValueIsWhatItsEpisodesEarn) {
  for (const Problem& problem : {testing::paper_instance("instance2"), testing::navigation_with_deadline(14),
                                 testing::with_random_rewards(testing::paper_instance("instance3"), 5)}) {
    const double exact = policy_value(problem);
    // Fewer under the sanitizers (ONTIME_TEST_SHARE), the bound below widening with them.
    const auto episodes = static_cast<std::uint64_t>(testing::repetitions_to_check(20'000));
    const double sampled = sampled_value(problem, episodes, 7);
    // Rewards lie in [0, 1], so their variance is at most the mean's v(1 - v).
    const double error = std::sqrt(exact * (1 - exact) / static_cast<double>(episodes));
    EXPECT_NEAR(sampled, exact, 4 * error + 1e-12) << problem.name();
  }
}

}  // namespace
}  // namespace ontime
