// Problems with more skeletons than a state holds inline: they load, validate, simulate and
// evaluate with every allocator that does not need the exact solver's compact state, and the
// exact solvers refuse them by name.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

TEST(WideState, CopiesAreDeepAndAssignmentsReuseTheirArrays) {
  State wide(300);
  ASSERT_EQ(wide.spent.capacity(), 300U);
  const std::size_t last = wide.spent.capacity() - 1;
  wide.spent[last] = 7;
  wide.refined[last / 2] = 2;
  State copy = wide;
  EXPECT_EQ(copy, wide);
  copy.spent[last] = 8;
  EXPECT_EQ(wide.spent[last], 7);
  EXPECT_NE(copy, wide);
  const std::uint16_t* array = copy.spent.data();
  copy = wide;  // same size: the heap array is reused
  EXPECT_EQ(copy.spent.data(), array);
  EXPECT_EQ(copy, wide);
  State narrow(3);
  EXPECT_EQ(narrow.spent.capacity(), static_cast<std::size_t>(kInlineSkeletons));
  EXPECT_NE(narrow, wide);
  narrow = wide;
  EXPECT_EQ(narrow, wide);
  narrow = State(3);
  EXPECT_EQ(narrow, State{});
}

TEST(WideState, ChoiceListsGrowBeyondTheInlineEntries) {
  ChoiceList choices;
  for (int k = 0; k < 40; ++k) choices.push_back(3 * k);
  ASSERT_EQ(choices.size(), 40U);
  EXPECT_EQ(choices[0], 0);
  EXPECT_EQ(choices[15], 45);
  EXPECT_EQ(choices[16], 48);
  EXPECT_EQ(choices[39], 117);
  int expected = 0;
  for (const int choice : choices) {
    EXPECT_EQ(choice, expected);
    expected += 3;
  }
}

// The skeletons of paper instance 1 followed by `extra` skeletons of two actions that can never
// be refined: no allocator should spend a step on them, and hidden worlds draw their times
// after those of instance 1's actions, so every episode is the one instance 1 alone has.
Problem padded_instance1(int extra) {
  const Problem base = testing::paper_instance("instance1");
  std::vector<Action> actions(base.actions().begin(), base.actions().end());
  std::vector<std::vector<int>> skeletons;
  for (int k = 0; k < base.skeleton_count(); ++k)
    skeletons.emplace_back(base.skeleton(k).begin(), base.skeleton(k).end());
  for (int i = 0; i < extra; ++i) {
    const int first = static_cast<int>(actions.size());
    for (const char* part : {"a", "b"}) {
      actions.push_back(Action{"hopeless" + std::to_string(i) + part, Distribution::from_pmf({0.0}),
                               Distribution::from_pmf({0.0, 1.0})});
    }
    skeletons.push_back({first, first + 1});
  }
  return Problem("instance1-padded", base.deadline(), base.step_seconds(), std::move(actions), std::move(skeletons));
}

TEST(WideProblem, ThreeHundredSkeletonsSimulateAsTheirUsefulSixteenDo) {
  const Problem narrow = testing::paper_instance("instance1");
  const Problem wide = padded_instance1(300 - narrow.skeleton_count());
  ASSERT_EQ(wide.skeleton_count(), 300);
  const Mdp narrow_mdp(narrow);
  const Mdp wide_mdp(wide);
  for (const char* solver :
       {"dp", "dp-rerun", "greedy", "round-robin", "thompson", "mcts", "first-found", "found-order-round-robin"}) {
    SCOPED_TRACE(solver);
    ParameterValues values;
    if (std::string_view(solver) == "mcts") values.set("iterations", "200");
    MonteCarloOptions options;
    options.episodes = std::string_view(solver) == "mcts" ? 200 : 4000;
    options.seed = 11;
    options.threads = 2;
    const MonteCarloResult expected =
        run_monte_carlo(narrow_mdp, make_allocator_factory(solver, narrow_mdp, values), options);
    const MonteCarloResult got = run_monte_carlo(wide_mdp, make_allocator_factory(solver, wide_mdp, values), options);
    if (std::string_view(solver) == "round-robin" || std::string_view(solver) == "found-order-round-robin") {
      // Round-robin turns to every skeleton in turn, the hopeless ones too: it loses. So does
      // its found-order variant, which reads no model and cannot see that they are hopeless.
      EXPECT_LT(got.successes, expected.successes);
    } else {
      // first-found reads no model either, but it turns past skeletons 0 .. 3 only when none of
      // them can succeed any more (the episode has ended): skeleton 0 is abandoned only when
      // a1_2 needs 5 steps (CT >= 6), and skeletons 1 .. 3, tried from then on, are abandoned
      // or known dead no earlier than CT = 12, when each needs at least 16 steps in all.
      EXPECT_EQ(got.successes, expected.successes);
    }
  }
}

TEST(WideProblem, ResultsDoNotDependOnTheThreadCount) {
  const Problem problem = testing::wide_instance(3, 300, 4, 60);
  ASSERT_EQ(problem.skeleton_count(), 300);
  const Mdp mdp(problem);
  for (const char* solver : {"dp-rerun", "thompson", "greedy"}) {
    SCOPED_TRACE(solver);
    MonteCarloOptions options;
    options.episodes = 600;
    options.seed = 2;
    options.threads = 1;
    const MonteCarloResult one = run_monte_carlo(mdp, make_allocator_factory(solver, mdp), options);
    options.threads = 2;
    const MonteCarloResult two = run_monte_carlo(mdp, make_allocator_factory(solver, mdp), options);
    EXPECT_EQ(one.successes, two.successes);
    EXPECT_GT(one.successes, 0U);
  }
}

TEST(WideProblem, InstanceFilesOfHundredsOfSkeletonsRoundTrip) {
  const Problem problem = testing::wide_instance(4, 400, 5, 200);
  const Problem again = parse_problem(problem_to_json(problem), "wide.json");
  ASSERT_EQ(again.skeleton_count(), 400);
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    ASSERT_EQ(std::vector<int>(again.skeleton(k).begin(), again.skeleton(k).end()),
              std::vector<int>(problem.skeleton(k).begin(), problem.skeleton(k).end()));
  }
}

TEST(WideProblem, TheExactSolversNameTheirLimit) {
  const Problem problem = testing::wide_instance(5, 17, 3, 20);
  const Mdp mdp(problem);
  try {
    OptimalSolver solver(mdp);
    FAIL() << "the optimal solver took 17 skeletons";
  } catch (const UsageError& error) {
    EXPECT_NE(std::string(error.what()).find("17 skeletons"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("at most 16"), std::string::npos) << error.what();
  }
  auto allocator = make_allocator_factory("dp-rerun", mdp)();
  EXPECT_THROW(evaluate_exactly(mdp, *allocator), UsageError);
  EXPECT_THROW(make_allocator_factory("optimal", mdp), UsageError);
  // Sixteen are still solved.
  const Problem sixteen = testing::wide_instance(5, 16, 2, 6);
  const Mdp sixteen_mdp(sixteen);
  EXPECT_GE(OptimalSolver(sixteen_mdp).solve(sixteen_mdp.start()), 0.0);
}

TEST(WideProblem, ASessionDrivesAWideProblem) {
  const Problem problem = testing::wide_instance(6, 250, 3, 40);
  const Mdp mdp(problem);
  auto allocator = make_allocator_factory("dp-rerun", mdp)();
  HiddenWorld world(problem, 9);
  Session session(mdp, *allocator, 0);
  int steps = 0;
  while (session.status() == Status::running) {
    const Decision decision = session.choose();
    ASSERT_GE(decision.skeleton, 0);
    ASSERT_LT(decision.skeleton, 250);
    if (decision.action < 0) {
      session.report_not_yet();
    } else {
      session.report(world.step(decision.action, session.state().spent[static_cast<std::size_t>(decision.skeleton)]));
    }
    ++steps;
  }
  EXPECT_EQ(session.steps_used(), steps);
  if (session.status() == Status::success) {
    EXPECT_GE(session.solution(), 0);
  }
}

}  // namespace
}  // namespace ontime
