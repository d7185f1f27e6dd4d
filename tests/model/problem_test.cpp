#include "ontime/model/problem.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <utility>

#include "ontime/util/error.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

Action simple(const std::string& id) {
  return Action{id, Distribution::from_pmf({0.0, 1.0}), Distribution::from_pmf({1.0})};
}

// Motion and backtrack as competing risks: by step 1 a motion has mass 0.2 and a backtrack 0.1,
// by step 2 a motion 0.3 more, by step 3 a backtrack 0.25 more; 0.15 never ends.
TEST(Problem, AnAttemptEndsWhereTheCumulativeMassPassesTheDraw) {
  const Action action{"a", Distribution::from_pmf({0.0, 0.2, 0.3}), Distribution::from_pmf({1.0}),
                      Distribution::from_pmf({0.0, 0.1, 0.0, 0.25})};
  const auto ends = [&action](double u, Steps spent = 0, Steps last = kNever) {
    const AttemptEnd end = draw_attempt_end(action, u, spent, last);
    return std::pair{end.step, end.found};
  };
  EXPECT_EQ(ends(0.1), std::pair(1, true));    // below 0.2
  EXPECT_EQ(ends(0.25), std::pair(1, false));  // in [0.2, 0.3): the backtrack of step 1
  EXPECT_EQ(ends(0.5), std::pair(2, true));    // in [0.3, 0.6)
  EXPECT_EQ(ends(0.7), std::pair(3, false));   // in [0.6, 0.85)
  EXPECT_EQ(ends(0.9), std::pair(kNever, false));
  EXPECT_EQ(ends(0.7, 0, 2), std::pair(kNever, false));  // its end lies beyond `last`
  // One step spent without an end: the draw covers the remaining 0.7, from 0.3 on.
  EXPECT_EQ(ends(0.0, 1), std::pair(2, true));
  EXPECT_EQ(ends(0.5, 1), std::pair(3, false));  // 0.3 + 0.5 x 0.7 = 0.65, in [0.6, 0.85)
}

TEST(Problem, PrefixTreeOfFigureOne) {
  const Problem problem = testing::paper_instance("figure1");
  ASSERT_EQ(problem.skeleton_count(), 3);
  const int d1 = problem.find_action("d1");
  const int d12 = problem.find_action("d12");
  const int d3 = problem.find_action("d3");
  ASSERT_GE(d1, 0);
  EXPECT_EQ(std::vector<int>(problem.members(d1).begin(), problem.members(d1).end()), (std::vector<int>{0, 1}));
  EXPECT_EQ(std::vector<int>(problem.members(d12).begin(), problem.members(d12).end()), (std::vector<int>{0}));
  EXPECT_EQ(problem.position(d1), 0);
  EXPECT_EQ(problem.position(d12), 1);
  EXPECT_EQ(problem.parent(d12), d1);
  EXPECT_EQ(problem.parent(d3), -1);
  EXPECT_FALSE(problem.completes_a_skeleton(d1));
  EXPECT_TRUE(problem.completes_a_skeleton(d12));
  EXPECT_TRUE(problem.completes_a_skeleton(d3));
}

TEST(Problem, SharingOfInstanceOne) {
  const Problem problem = testing::paper_instance("instance1");
  const int shared_first = problem.find_action("a2_1");
  const int shared_second = problem.find_action("a2_2");
  EXPECT_EQ(problem.members(shared_first).size(), 3U);
  EXPECT_EQ(problem.members(shared_second).size(), 2U);
  EXPECT_EQ(problem.members(problem.find_action("a1_1")).size(), 1U);
}

TEST(Problem, RejectsBrokenRules) {
  const auto make = [](std::vector<std::vector<int>> skeletons, Steps deadline = 5) {
    return Problem("p", deadline, 1.0, {simple("a"), simple("b"), simple("c")}, std::move(skeletons));
  };
  EXPECT_NO_THROW(make({{0, 1}, {0, 2}}));
  EXPECT_NO_THROW(make({{0}, {0, 1}}));              // a skeleton may be a prefix of another
  EXPECT_THROW(make({{0, 1}, {0, 1}}), UsageError);  // listed twice
  EXPECT_THROW(make({{0, 1, 0}}), UsageError);       // repeats an action
  EXPECT_THROW(make({{0, 1}, {2, 1}}), UsageError);  // shared after different prefixes
  EXPECT_THROW(make({{0, 1}, {1}}), UsageError);     // shared at another position
  EXPECT_THROW(make({{}}), UsageError);              // empty skeleton
  EXPECT_THROW(make({{3}}), UsageError);             // unknown action
  EXPECT_THROW(make({{0}}, 0), UsageError);          // deadline below 1
  EXPECT_THROW(make({{0}}, Problem::kMaxDeadline + 1), UsageError);
  EXPECT_THROW(make({}), UsageError);                                                 // no skeleton
  EXPECT_THROW(Problem("p", 5, 1.0, {simple("a"), simple("a")}, {{0}}), UsageError);  // duplicate id
  Action zero_planning{"z", Distribution::from_pmf({0.5, 0.5}), Distribution::from_pmf({1.0})};
  EXPECT_THROW(Problem("p", 5, 1.0, {zero_planning}, {{0}}), UsageError);
}

TEST(Problem, DistributionsOfAnotherInstanceByActionId) {
  const Problem structure("truth", 5, 0.5, {simple("a"), simple("b")}, {{0, 1}, {0}}, "the world's");
  // The belief lists the actions in the other order, with other distributions, and an action
  // the structure does not use.
  const Action belief_b{"b", Distribution::from_pmf({0.0, 0.25, 0.75}), Distribution::from_pmf({0.0, 1.0})};
  const Action belief_a{"a", Distribution::from_pmf({0.0, 0.0, 0.5}), Distribution::from_pmf({1.0})};
  const Problem belief("belief", 5, 0.5, {belief_b, simple("c"), belief_a}, {{0}, {1}, {2}});
  const Problem planned = with_distributions_of(structure, belief);
  EXPECT_EQ(planned.name(), "truth");
  EXPECT_EQ(planned.description(), "the world's");
  ASSERT_EQ(planned.action_count(), 2);
  EXPECT_EQ(planned.action(0).id, "a");
  EXPECT_EQ(planned.action(0).planning.pmf(2), 0.5);
  EXPECT_EQ(planned.action(0).planning.never(), 0.5);
  EXPECT_EQ(planned.action(1).planning.pmf(1), 0.25);
  EXPECT_EQ(planned.action(1).execution.pmf(1), 1.0);
  ASSERT_EQ(planned.skeleton_count(), 2);
  EXPECT_EQ(planned.action_at(0, 1), 1);
  EXPECT_EQ(planned.action_at(1, 0), 0);

  const Problem lacking("belief", 5, 0.5, {belief_b}, {{0}});
  EXPECT_THROW(with_distributions_of(structure, lacking), UsageError);
  const Problem later("belief", 6, 0.5, {belief_b, belief_a}, {{0}, {1}});
  EXPECT_THROW(with_distributions_of(structure, later), UsageError);
  const Problem coarser("belief", 5, 1.0, {belief_b, belief_a}, {{0}, {1}});
  EXPECT_THROW(with_distributions_of(structure, coarser), UsageError);
}

}  // namespace
}  // namespace ontime
