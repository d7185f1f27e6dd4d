#include "ontime/learn/online_belief.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "ontime/mdp/mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/session.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"

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

// The total mass of a distribution within its steps (1 - never).
double mass(const Distribution& d) { return 1.0 - d.never(); }

// data/instances/kitchen-grasps.json's move+place(B1,S) is found at step 5 with 0.001 and
// backtracks at 1 and 2 with 0.978 and 0.021: planning and backtracking take all its mass. Five
// attempts found at 5 used to raise its planning mass alone, past 1 with the backtrack kept, and the
// believed instance was refused ("planning and backtrack probabilities sum above 1"). Learned
// together, with strength 10 (a = 10 p, b = 10 q, c = 10 S, plus the attempts): step 1 has
// b = 9.78 and c = 0.22 + 5 of a total of 15, step 2 b = 0.21 and c = 0.01 + 5, steps 3 and 4
// c only, step 5 a = 0.01 + 5 and nothing else. So q(1) = 9.78 / 15, q(2) = 0.21 / 15 and
// p(5) = 5.01 / 15: they sum to 1.
TEST(OnlineBelief, ABacktrackingActionFoundMoreOftenThanItsPriorSaysStaysAValidInstance) {
  const Problem prior = load_problem(testing::source_path("data/instances/kitchen-grasps.json"));
  const std::string id = "move+place(B1,S)";
  OnlineBelief belief(prior, 10.0);
  for (int i = 0; i < 5; ++i) belief.observe(id, ActionAttempt{5, true});
  const Problem believed = belief.believed();
  const Action& action = believed.action(believed.find_action(id));
  EXPECT_NEAR(action.planning.pmf(5), 5.01 / 15, 1e-12);
  EXPECT_NEAR(mass(action.planning), 5.01 / 15, 1e-12);
  EXPECT_NEAR(action.backtrack.pmf(1), 9.78 / 15, 1e-12);
  EXPECT_NEAR(action.backtrack.pmf(2), 0.21 / 15, 1e-12);
  EXPECT_NEAR(mass(action.backtrack), 9.99 / 15, 1e-12);
  ASSERT_EQ(action.culprits.size(), 1u);  // the prior's
  EXPECT_EQ(action.culprits[0].id, "move+pick(B1)");
  EXPECT_EQ(action.culprits[0].probability, 1.0);
  EXPECT_EQ(belief.planning(id), action.planning);
  EXPECT_EQ(belief.backtrack(id), action.backtrack);
  // The other actions keep their prior bit for bit.
  for (int a = 0; a < prior.action_count(); ++a) {
    if (prior.action(a).id == id) continue;
    EXPECT_EQ(believed.action(a).planning, prior.action(a).planning);
    EXPECT_EQ(believed.action(a).backtrack, prior.action(a).backtrack);
  }
}

// What a session saw in grasp-and-place (tests/run/session_test.cpp: pick(A) found after 1 step,
// then discarded, then found after 2; place(A,R1) backtracked after 2; place(A,R2) cut off after
// 1), learned attempt by attempt: place(A,R1), which backtracks, learns both distributions as
// PlanningPosterior does with its prior over the deadline; pick(A) and place(A,R2), which do not
// backtrack, learn their planning time.
TEST(OnlineBelief, LearnsTheAttemptsABacktrackEndedAsCompetingRisks) {
  const Problem problem = load_problem(testing::source_path("data/instances/backtracking/grasp-and-place.json"));
  const Mdp mdp(problem);
  Session session(mdp);
  for (const auto& [skeleton, observation] : std::vector<std::pair<int, Observation>>{{0, Observation::found(1)},
                                                                                      {1, Observation::not_yet()},
                                                                                      {0, Observation::not_yet()},
                                                                                      {0, Observation::backtracked(0)},
                                                                                      {0, Observation::not_yet()},
                                                                                      {0, Observation::found(1)}}) {
    session.decide(skeleton);
    session.report(observation);
  }
  OnlineBelief belief(problem, 3.0);
  belief.observe(problem, session.attempts());
  EXPECT_EQ(belief.observations(), 4u);

  const auto prior_of = [&](const char* id) { return problem.action(problem.find_action(id)); };
  PlanningPosterior place(prior_of("place(A,R1)").planning, prior_of("place(A,R1)").backtrack, 12, 3.0);
  place.observe_backtrack(2);
  PlanningPosterior pick(prior_of("pick(A)").planning, 12, 3.0);
  pick.observe_found(1);
  pick.observe_found(2);
  PlanningPosterior other(prior_of("place(A,R2)").planning, 12, 3.0);
  other.observe_cut_off(1);
  const Problem believed = belief.believed();
  EXPECT_EQ(believed.action(1).planning, place.mean());
  EXPECT_EQ(believed.action(1).backtrack, place.backtrack_mean());
  EXPECT_EQ(believed.action(0).planning, pick.mean());
  EXPECT_EQ(believed.action(2).planning, other.mean());
  EXPECT_EQ(believed.action(3).planning, problem.action(3).planning);
  // By hand: place(A,R1) has p(1) = 0.3, p(2) = 0.2, q(2) = 0.4, strength 3. The backtrack at 2
  // adds 1 to c_1 (3 x 0.7 + 1 = 3.1) and to b_2 (1.2 + 1 = 2.2): the hazards of step 1 are
  // 0.9 / 4 and 0, of step 2 0.6 / 3.1 and 2.2 / 3.1 (c_2 = 3 x 0.1 = 0.3). So p(1) = 0.225,
  // p(2) = 0.775 x 0.6 / 3.1 = 0.15, q(2) = 0.775 x 2.2 / 3.1 = 0.55, never 0.075.
  EXPECT_NEAR(believed.action(1).planning.pmf(1), 0.225, 1e-12);
  EXPECT_NEAR(believed.action(1).planning.pmf(2), 0.15, 1e-12);
  EXPECT_NEAR(believed.action(1).backtrack.pmf(2), 0.55, 1e-12);
  EXPECT_NEAR(believed.action(1).backtrack.never(), 0.45, 1e-12);

  // An action whose prior does not backtrack has no culprit to blame: a backtrack of it counts as
  // an attempt cut off there.
  OnlineBelief cut(problem, 3.0), backtracked(problem, 3.0);
  cut.observe("pick(A)", ActionAttempt{2, false});
  backtracked.observe("pick(A)", ActionAttempt{0, false, {EndedAttempt{2, false, true}}});
  EXPECT_EQ(backtracked.believed().action(0).planning, cut.believed().action(0).planning);
  EXPECT_EQ(backtracked.believed().action(0).backtrack, Distribution{});
}

}  // namespace
}  // namespace ontime
