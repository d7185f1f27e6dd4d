// Rewards beyond success (SPEC §8) in the allocators' choices: a fast plan worth little against a
// slower one worth more that still meets the deadline.
#include <gtest/gtest.h>

#include <string>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"

namespace ontime {
namespace {

// Skeleton 0 is refined in 1 step and executed in 1; skeleton 1 in 3 and 2: both meet the
// deadline of 8 for sure. `rewards` is the instance's "rewards" entry (empty: none).
Problem fast_or_worthy(const std::string& rewards) {
  return parse_problem(R"({"deadline": 8, "actions": {
      "fast": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"1": 1.0}}},
      "worthy": {"planning": {"pmf": {"3": 1.0}}, "execution": {"pmf": {"2": 1.0}}}},
      "skeletons": [["fast"], ["worthy"]])" +
                           (rewards.empty() ? std::string() : ", \"rewards\": " + rewards) + "}",
                       "fast-or-worthy.json");
}

TEST(RewardChoices, EveryModelReadingAllocatorGoesForTheWorthierPlanAndWithoutRewardsForTheFaster) {
  const Problem plain = fast_or_worthy("");
  const Problem rewarded = fast_or_worthy("[0.4, {\"value\": 1.0, \"per_step\": 0.05}]");
  const Mdp plain_mdp(plain), rewarded_mdp(rewarded);
  for (const char* name : {"optimal", "dp", "dp-rerun", "thompson", "mcts", "branch-and-bound"}) {
    const auto without = make_allocator_factory(name, plain_mdp)();
    without->begin_episode(1);
    EXPECT_EQ(without->choose(plain_mdp.start()), 0) << name;
    const auto with = make_allocator_factory(name, rewarded_mdp)();
    with->begin_episode(1);
    EXPECT_EQ(with->choose(rewarded_mdp.start()), 1) << name;
  }
  // Refining the worthy plan first finishes it at step 5: worth 1 - 0.05 * 5.
  const auto optimal = make_allocator_factory("optimal", rewarded_mdp)();
  const ExactEvaluation exact = evaluate_exactly(rewarded_mdp, *optimal);
  EXPECT_DOUBLE_EQ(exact.expected_reward, 0.75);
  EXPECT_EQ(exact.success_probability, 1.0);
}

}  // namespace
}  // namespace ontime
