#include "ontime/learn/online_belief.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "ontime/mdp/mdp.hpp"
#include "ontime/run/session.hpp"
#include "ontime/util/error.hpp"

namespace ontime {
namespace {

// Two actions over a deadline of 2 steps: "a" with p(1) = 1/2, p(2) = 1/4, never 1/4 (the prior
// of online_update_test's hand-computed cases), "b" found at step 1 always; executions of 0 steps.
Problem prior_library() {
  const Distribution now = Distribution::from_pmf({1.0});
  std::vector<Action> actions{{"a", Distribution::from_pmf({0.0, 0.5, 0.25}), now},
                              {"b", Distribution::from_pmf({0.0, 1.0}), now}};
  return {"library", 2, 1.0, std::move(actions), {{0}, {1}}};
}

// An episode's problem whose node "a#2" is the action "a" reached under "b".
Problem episode_problem() {
  const Distribution now = Distribution::from_pmf({1.0});
  std::vector<Action> actions{{"a", Distribution::from_pmf({0.0, 1.0}), now},
                              {"b", Distribution::from_pmf({0.0, 1.0}), now},
                              {"a#2", Distribution::from_pmf({0.0, 1.0}), now}};
  return {"episode", 2, 1.0, std::move(actions), {{0}, {1, 2}}};
}

TEST(ActionBaseId, StripsATrailingHashAndDigitsOnly) {
  EXPECT_EQ(action_base_id("move(R8,R9)#2"), "move(R8,R9)");
  EXPECT_EQ(action_base_id("move(R8,R9)#12"), "move(R8,R9)");
  EXPECT_EQ(action_base_id("move(R8,R9)"), "move(R8,R9)");
  EXPECT_EQ(action_base_id("pick#x"), "pick#x");
  EXPECT_EQ(action_base_id("pick#"), "pick#");
  EXPECT_EQ(action_base_id("#2"), "#2");
}

TEST(OnlineBelief, WithoutAttemptsEveryActionKeepsItsPriorBitForBit) {
  const OnlineBelief belief(prior_library(), 2.0);
  const Problem believed = belief.believed();
  EXPECT_EQ(believed.action(0).planning, prior_library().action(0).planning);
  EXPECT_EQ(believed.action(1).planning, prior_library().action(1).planning);
  EXPECT_EQ(belief.planning("a#2"), prior_library().action(0).planning);
  EXPECT_EQ(belief.observations(), 0u);
}

// The hand-computed case of PlanningPosterior: found at 2 then cut off after 1 gives p(1) = 1/4,
// p(2) = 9/16, never 3/16; the node "a#2" and the action "a" learn together, "b" is untouched.
TEST(OnlineBelief, AttemptsOnANodeAndOnItsBaseUpdateOnePosterior) {
  OnlineBelief belief(prior_library(), 2.0);
  belief.observe("a#2", ActionAttempt{2, true});
  belief.observe("a", ActionAttempt{1, false});
  belief.observe("b", ActionAttempt{0, false});  // no effort: no data
  EXPECT_EQ(belief.observations(), 2u);
  const Distribution a = belief.planning("a");
  EXPECT_DOUBLE_EQ(a.pmf(1), 0.25);
  EXPECT_DOUBLE_EQ(a.pmf(2), 9.0 / 16);
  EXPECT_NEAR(a.never(), 3.0 / 16, 1e-15);
  EXPECT_EQ(belief.planning("a#7"), a);
  EXPECT_EQ(belief.planning("b"), prior_library().action(1).planning);

  // Applied to an episode's problem: both nodes of "a" take its posterior.
  const Problem applied = belief.believed_for(episode_problem());
  EXPECT_EQ(applied.action(0).planning, a);
  EXPECT_EQ(applied.action(2).planning, a);
  EXPECT_EQ(applied.action(1).planning, prior_library().action(1).planning);
}

TEST(OnlineBelief, LearnsFromWhatASessionSaw) {
  // Skeleton 0 = (a), skeleton 1 = (b, a#2): refine b (found at step 1), then a#2 gets a step
  // that finds nothing, then a finds at its first step. The session records each action's attempt.
  const Problem problem = episode_problem();
  Session session(problem, nullptr, 0);
  session.decide(1);
  session.report_refined(0);
  session.decide(1);
  session.report_not_yet();
  const std::vector<ActionAttempt>& attempts = session.attempts();
  ASSERT_EQ(attempts.size(), 3u);
  EXPECT_EQ(attempts[1].effort, 1);
  EXPECT_TRUE(attempts[1].found);
  EXPECT_EQ(attempts[2].effort, 1);
  EXPECT_FALSE(attempts[2].found);
  EXPECT_EQ(attempts[0].effort, 0);

  OnlineBelief belief(prior_library(), 2.0);
  belief.observe(session.problem(), session.attempts());
  OnlineBelief by_hand(prior_library(), 2.0);
  by_hand.observe("b", ActionAttempt{1, true});
  by_hand.observe("a", ActionAttempt{1, false});
  EXPECT_EQ(belief.believed().action(0).planning, by_hand.believed().action(0).planning);
  EXPECT_EQ(belief.believed().action(1).planning, by_hand.believed().action(1).planning);
  EXPECT_EQ(belief.observations(), 2u);
}

TEST(OnlineBelief, BadInputIsRefusedBeforeAnythingIsObserved) {
  EXPECT_THROW(OnlineBelief(prior_library(), 0.0), UsageError);
  EXPECT_THROW(OnlineBelief(prior_library(), -1.0), UsageError);
  OnlineBelief belief(prior_library(), 2.0);
  EXPECT_THROW(belief.observe("c", ActionAttempt{1, true}), UsageError);
  EXPECT_THROW(belief.planning("c"), UsageError);
  const std::vector<ActionAttempt> two(2);
  EXPECT_THROW(belief.observe(episode_problem(), two), UsageError);
  // A problem with an action the belief lacks: nothing of it is observed.
  const Distribution now = Distribution::from_pmf({1.0});
  const Problem other("other", 2, 1.0,
                      {{"a", Distribution::from_pmf({0.0, 1.0}), now}, {"c", Distribution::from_pmf({0.0, 1.0}), now}},
                      {{0}, {1}});
  const std::vector<ActionAttempt> both{{1, true}, {1, true}};
  EXPECT_THROW(belief.observe(other, both), UsageError);
  EXPECT_EQ(belief.observations(), 0u);
}

}  // namespace
}  // namespace ontime
