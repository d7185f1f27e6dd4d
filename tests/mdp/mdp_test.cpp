#include "ontime/mdp/mdp.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

struct Outcome {
  double probability;
  Status status;
  State next;
};

std::vector<Outcome> outcomes(const Mdp& mdp, const State& state, int choice) {
  std::vector<Outcome> result;
  mdp.for_each_outcome(state, choice, [&](double p, Status s, const State& next) { result.push_back({p, s, next}); });
  return result;
}

class FigureOne : public ::testing::Test {
 protected:
  Problem problem = testing::paper_instance("figure1");
  Mdp mdp{problem};
};

TEST_F(FigureOne, FirstStepOnTheSharedActionHasThreeOutcomes) {
  const auto result = outcomes(mdp, mdp.start(), 0);
  ASSERT_EQ(result.size(), 3U);
  // Not found (0.5): PT advances for both sharing skeletons.
  EXPECT_DOUBLE_EQ(result[0].probability, 0.5);
  EXPECT_EQ(result[0].status, Status::running);
  EXPECT_EQ(result[0].next.time, 1);
  EXPECT_EQ(result[0].next.spent[0], 1);
  EXPECT_EQ(result[0].next.spent[1], 1);
  EXPECT_EQ(result[0].next.spent[2], 0);
  // Found, executes in 1 step (0.25): both skeletons move on, ET = 1.
  EXPECT_DOUBLE_EQ(result[1].probability, 0.25);
  EXPECT_EQ(result[1].status, Status::running);
  EXPECT_EQ(result[1].next.refined[0], 1);
  EXPECT_EQ(result[1].next.refined[1], 1);
  EXPECT_EQ(result[1].next.execution[0], 1);
  EXPECT_EQ(result[1].next.execution[1], 1);
  EXPECT_EQ(result[1].next.spent[0], 0);
  // Found, executes in 10 steps (0.25): beyond the deadline, saturated at D + 1.
  EXPECT_DOUBLE_EQ(result[2].probability, 0.25);
  EXPECT_EQ(result[2].next.execution[0], 6);
  EXPECT_EQ(result[2].next.execution[1], 6);
}

TEST_F(FigureOne, SharingSkeletonsAreTheSameChoice) {
  const auto first = outcomes(mdp, mdp.start(), 0);
  const auto second = outcomes(mdp, mdp.start(), 1);
  ASSERT_EQ(first.size(), second.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].probability, second[i].probability);
    EXPECT_EQ(first[i].next, second[i].next);
  }
}

TEST_F(FigureOne, DeterministicPlanningFinishesOnItsStep) {
  State state = mdp.start();
  for (int step = 0; step < 2; ++step) {
    const auto result = outcomes(mdp, state, 2);
    ASSERT_EQ(result.size(), 1U);  // hazard 0 before step 3
    EXPECT_DOUBLE_EQ(result[0].probability, 1.0);
    state = result[0].next;
  }
  EXPECT_EQ(state.spent[2], 2);
  const auto last = outcomes(mdp, state, 2);
  ASSERT_EQ(last.size(), 2U);
  EXPECT_EQ(last[0].status, Status::success);  // CT 3 + ET 1 <= 5
  EXPECT_DOUBLE_EQ(last[0].probability, 0.5);
  EXPECT_EQ(last[1].status, Status::failure);  // too slow, and sigma1/2 cannot fit anymore
  EXPECT_DOUBLE_EQ(last[1].probability, 0.5);
}

TEST_F(FigureOne, RefiningTheSecondActionCompletesItsSkeleton) {
  State state = mdp.start();
  ASSERT_EQ(mdp.apply(state, 0, Observation::found(1)), Status::running);
  EXPECT_EQ(mdp.next_action(state, 0), problem.find_action("d12"));
  EXPECT_EQ(mdp.next_action(state, 1), problem.find_action("d22"));
  State via_first = state;
  ASSERT_EQ(mdp.apply(via_first, 0, Observation::found(1)), Status::success);  // 2 + 2 <= 5
  EXPECT_EQ(mdp.completed_skeleton(via_first, 0), 0);
  State via_second = state;
  ASSERT_EQ(mdp.apply(via_second, 1, Observation::found(1)), Status::success);
  EXPECT_EQ(mdp.completed_skeleton(via_second, 1), 1);
  // After the split, refining d12 leaves sigma2 untouched.
  State split = state;
  ASSERT_EQ(mdp.apply(split, 0, Observation::found(10)), Status::running);
  EXPECT_EQ(split.refined[0], 2);
  EXPECT_EQ(split.refined[1], 1);
  EXPECT_EQ(split.execution[1], 1);
}

TEST_F(FigureOne, FailsAsSoonAsNoSkeletonCanSucceed) {
  State state = mdp.start();
  // d1 not found at step 1: sigma1 and sigma2 now need >= 3 + 1 + 2 more steps; sigma3 still fits.
  ASSERT_EQ(mdp.apply(state, 0, Observation::not_yet()), Status::running);
  EXPECT_FALSE(mdp.can_succeed(state, 0));
  EXPECT_FALSE(mdp.can_succeed(state, 1));
  EXPECT_TRUE(mdp.can_succeed(state, 2));
  // One idle-like step lost on sigma1 leaves sigma3 (3 steps + 1) out of reach too.
  EXPECT_EQ(mdp.apply(state, 0, Observation::not_yet()), Status::failure);
}

TEST_F(FigureOne, RejectsImpossibleObservations) {
  State state = mdp.start();
  EXPECT_THROW(mdp.apply(state, 3, Observation::not_yet()), UsageError);
  EXPECT_THROW(mdp.apply(state, -1, Observation::not_yet()), UsageError);
  State negative = mdp.start();
  EXPECT_THROW(mdp.apply(negative, 0, Observation::found(-2)), UsageError);
  EXPECT_EQ(negative, mdp.start());  // a rejected observation changes nothing
}

TEST(Mdp, IdleStepOnAFullyRefinedSkeleton) {
  // sigma0 = (a) refined too slowly; choosing it again only spends time.
  const Problem problem(
      "idle", 6, 1.0,
      {Action{"a", Distribution::from_pmf({0.0, 1.0}), Distribution::from_pmf({0, 0, 0, 0, 0, 0, 1.0})},
       Action{"b", Distribution::from_pmf({0.0, 0.0, 1.0}), Distribution::from_pmf({1.0})}},
      {{0}, {1}});
  const Mdp mdp(problem);
  State state = mdp.start();
  ASSERT_EQ(mdp.apply(state, 0, Observation::found(6)), Status::running);  // 1 + 6 > 6
  EXPECT_EQ(mdp.next_action(state, 0), -1);
  EXPECT_FALSE(mdp.can_succeed(state, 0));
  const auto result = outcomes(mdp, state, 0);
  ASSERT_EQ(result.size(), 1U);
  EXPECT_EQ(result[0].next.time, 2);
  EXPECT_EQ(result[0].next.refined, state.refined);
  State idle = state;
  EXPECT_THROW(mdp.apply(idle, 0, Observation::found(1)), UsageError);
  EXPECT_EQ(idle, state);
}

TEST(Mdp, FailsAtTheDeadline) {
  const Problem problem("deadline", 2, 1.0,
                        {Action{"a", Distribution::from_pmf({0.0, 0.5, 0.0, 0.5}), Distribution::from_pmf({1.0})}},
                        {{0}});
  const Mdp mdp(problem);
  State state = mdp.start();
  ASSERT_EQ(mdp.apply(state, 0, Observation::not_yet()), Status::failure);  // step 3 cannot come
  State found = mdp.start();
  ASSERT_EQ(mdp.apply(found, 0, Observation::found(1)), Status::success);  // 1 + 1 <= 2
}

// Outcome probabilities of every choice in every reachable state sum to one.
TEST(Mdp, OutcomeProbabilitiesSumToOne) {
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const Problem problem = testing::random_instance(seed);
    const Mdp mdp(problem);
    std::vector<State> frontier{mdp.start()};
    int visited = 0;
    while (!frontier.empty() && visited < 400) {
      const State state = frontier.back();
      frontier.pop_back();
      ++visited;
      for (int k = 0; k < mdp.skeleton_count(); ++k) {
        double total = 0;
        mdp.for_each_outcome(state, k, [&](double p, Status status, const State& next) {
          EXPECT_GT(p, 0.0);
          total += p;
          if (status == Status::running) frontier.push_back(next);
        });
        EXPECT_NEAR(total, 1.0, 1e-12) << "seed " << seed;
      }
    }
  }
}

}  // namespace
}  // namespace ontime
