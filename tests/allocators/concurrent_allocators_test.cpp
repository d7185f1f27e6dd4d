// The registry's allocators when the robot acts while planning (SPEC §10): which kinds take the
// mode and with which commit rule, the optimal allocator at the optimum, the eager rule around the
// plan-first kinds, and the plan-first view they decide from.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/allocators/round_robin.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

// The exact value of the allocators `factory` makes, by the solver's policy mode.
double exact_value(const ConcurrentMdp& mdp, const ConcurrentAllocatorFactory& factory) {
  const auto allocator = factory();
  allocator->begin_episode(0);
  ConcurrentSolver evaluation(mdp, [&](const ConcurrentState& state) { return allocator->choose(state); });
  return evaluation.solve(mdp.start());
}

double optimum(const ConcurrentMdp& mdp) {
  ConcurrentSolver solver(mdp);
  return solver.solve(mdp.start());
}

Problem acting(Problem problem) { return problem.with_acting(Acting::concurrent); }

// A random walk's start, one time in two when the robot may start something: true when it started
// the lowest startable action (`state` moved on), false when that ended the episode, nullopt when
// it started nothing.
std::optional<bool> maybe_start(const ConcurrentMdp& mdp, ConcurrentState& state, SplitMix64& generator) {
  const std::vector<int> starts = mdp.startable(state);
  if (starts.empty() || generator() % 2 != 0) return std::nullopt;
  const ConcurrentMdp::StartOutcome started = mdp.start_action(state, starts.front());
  if (started.ends) return false;
  state = started.next;
  return true;
}

TEST(ConcurrentAllocators, TheKindsWithACommitRuleAreThoseDocumented) {
  // Every built-in kind takes the mode.
  EXPECT_EQ(allocator_registry().acting_names(), allocator_registry().names());
  for (const AllocatorKind& kind : allocator_registry().kinds()) {
    EXPECT_EQ(kind.acts_while_planning(), !kind.commit_rule.empty()) << kind.name;
  }
  const ConcurrentMdp mdp(acting(testing::paper_instance("instance1")));
  // A kind added without a commit rule (an extension's) is refused, naming those with one.
  AllocatorKind plan_first_only = allocator_registry().find("round-robin");
  plan_first_only.name = "plan-first-only";
  plan_first_only.commit_rule.clear();
  allocator_registry().add(plan_first_only);
  try {
    (void)make_concurrent_allocator_factory("plan-first-only", mdp);
    ADD_FAILURE() << "a kind without a commit rule was accepted";
  } catch (const UsageError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("'plan-first-only' does not act while planning (SPEC §10)"), std::string::npos) << message;
    EXPECT_NE(message.find("optimal, mcts, dp, dp-rerun, ppo, round-robin"), std::string::npos) << message;
  }
  allocator_registry().remove("plan-first-only");
  // Parameters are checked as for plan-first kinds.
  EXPECT_THROW((void)make_concurrent_allocator_factory("dp-rerun", mdp, {{"aggregation", "most"}}), UsageError);
  EXPECT_THROW((void)make_concurrent_allocator_factory("dp-rerun", mdp, {{"no-such", "1"}}), UsageError);
}

TEST(ConcurrentAllocators, TheOptimalAllocatorEarnsTheOptimum) {
  // Its moves include the complete plans the solver values at 1 without a move of its own.
  for (std::uint64_t seed = 0; seed < 120; ++seed) {
    Problem problem = testing::random_instance(seed + 500, 4, 3, 10);
    if (seed % 2 == 1) problem = testing::with_random_rewards(problem, seed);
    const ConcurrentMdp mdp(acting(problem));
    EXPECT_NEAR(exact_value(mdp, make_concurrent_allocator_factory("optimal", mdp)), optimum(mdp), 1e-12)
        << "seed " << seed;
  }
}

TEST(ConcurrentAllocators, EveryStationaryKindIsAPolicyOfTheModel) {
  // Valued exactly, no kind is worth more than the optimum, and each reaches it where the
  // optimum is certain (instance 1). (ppo, which needs a policy trained per instance, is valued in
  // tests/learn/concurrent_ppo_test.cpp.)
  std::vector<std::string> stationary;
  for (const std::string& name : allocator_registry().acting_names()) {
    const Capabilities& capabilities = allocator_registry().find(name).capabilities;
    if (capabilities.has(Capability::stationary) && !capabilities.has(Capability::needs_policy)) {
      stationary.push_back(name);
    }
  }
  ASSERT_EQ(stationary.size(), 8U);
  for (std::uint64_t seed = 0; seed < 60; ++seed) {
    const ConcurrentMdp mdp(acting(testing::random_instance(seed + 900, 4, 3, 10)));
    const double best = optimum(mdp);
    for (const std::string& name : stationary) {
      const double value = exact_value(mdp, make_concurrent_allocator_factory(name, mdp));
      EXPECT_GE(value, 0.0) << name << " seed " << seed;
      EXPECT_LE(value, best + 1e-12) << name << " seed " << seed;
    }
  }
  const ConcurrentMdp first(acting(testing::paper_instance("instance1")));
  for (const std::string name : {"optimal", "dp-rerun", "dp", "greedy", "averaged"}) {
    EXPECT_NEAR(exact_value(first, make_concurrent_allocator_factory(name, first)), 1.0, 1e-12) << name;
  }
}

Problem two_moves() {
  // a is found in 1 step and runs 3; b is found after 3 more steps and runs 1; c is found in 2
  // steps and runs 1; deadline 6.
  return parse_problem(R"({"deadline": 6, "acting": "concurrent",
    "actions": {"a": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"3": 1}}},
                "b": {"planning": {"pmf": {"3": 1}}, "execution": {"pmf": {"1": 1}}},
                "c": {"planning": {"pmf": {"2": 1}}, "execution": {"pmf": {"1": 1}}}},
    "skeletons": [["a", "b"], ["c"]]})",
                       "two-moves");
}

TEST(ConcurrentAllocators, TheEagerRuleStartsTheChosenSkeletonsActionOnceItIsRefined) {
  const ConcurrentMdp mdp(two_moves());
  // Round-robin chooses skeleton CT mod 2: a at step 0.
  EagerCommitAllocator eager(mdp, std::make_unique<RoundRobinAllocator>(2));
  eager.begin_episode(0);
  ConcurrentState state = mdp.start();
  EXPECT_EQ(eager.choose(state), (ConcurrentMdp::Move{-1, 0}));
  state = mdp.step(state, 0, Observation::found(3));  // a refined at CT 1
  // Round-robin now chooses skeleton 1 (c), whose next execution is not refined: a step on c.
  EXPECT_EQ(eager.choose(state), (ConcurrentMdp::Move{-1, 1}));
  state = mdp.step(state, 1, Observation::not_yet());  // CT 2: round-robin chooses a's skeleton again
  EXPECT_EQ(eager.choose(state), (ConcurrentMdp::Move{0, ConcurrentMdp::kWait}));  // starts a, dropping c
  state = mdp.start_action(state, 0).next;
  EXPECT_FALSE(ConcurrentMdp::is_live(state, 1));
  // The robot is busy until 5 and b can be found at 5 and run to 6: a step on b.
  EXPECT_EQ(eager.choose(state), (ConcurrentMdp::Move{-1, 0}));
  // A complete plan runs at once, the planner idle while the robot is busy.
  ConcurrentState complete = mdp.step(mdp.step(mdp.start(), 1, Observation::not_yet()), 1, Observation::found(1));
  EXPECT_EQ(mdp.complete_plan(complete), 1);
  EXPECT_EQ(eager.choose(complete), (ConcurrentMdp::Move{2, ConcurrentMdp::kWait}));
}

TEST(ConcurrentAllocators, ThePlanFirstViewNeverPromisesWhatActingCannotKeep) {
  // Along random walks: a skeleton that can succeed plan-first in the view can finish acting
  // while planning; a dropped one cannot succeed in the view.
  for (std::uint64_t seed = 0; seed < 80; ++seed) {
    const ConcurrentMdp mdp(acting(testing::random_instance(seed + 1300, 4, 3, 10)));
    const Mdp& plan_first = mdp.plan_first_mdp();
    State view = plan_first.start();
    SplitMix64 generator(seed);
    ConcurrentState state = mdp.start();
    std::vector<std::pair<double, ConcurrentState>> outcomes;
    while (mdp.any_live(state) && ConcurrentMdp::time(state) < mdp.deadline()) {
      plan_first_view(mdp, state, view);
      for (int k = 0; k < mdp.skeleton_count(); ++k) {
        if (plan_first.can_succeed(view, k)) {
          EXPECT_TRUE(ConcurrentMdp::is_live(state, k));
          EXPECT_LE(mdp.earliest_finish(state, k), mdp.deadline());
        }
      }
      if (const std::optional<bool> started = maybe_start(mdp, state, generator)) {
        if (*started) continue;
        break;
      }
      const ChoiceList choices = mdp.refine_choices(state);
      const int choice =
          choices.empty() ? ConcurrentMdp::kWait : choices[static_cast<std::size_t>(generator() % choices.size())];
      outcomes.clear();
      mdp.for_each_step_outcome(state, choice, [&](double probability, const ConcurrentState& next) {
        outcomes.emplace_back(probability, next);
      });
      state = outcomes[sample_index(
                           outcomes.size(), [&](std::size_t i) { return outcomes[i].first; }, generator)]
                  .second;
    }
  }
}

TEST(ConcurrentAllocators, AnObservedStepIsTheModelsOutcome) {
  // ConcurrentMdp::step, which sessions use, against the outcomes the solvers enumerate.
  for (std::uint64_t seed = 0; seed < 60; ++seed) {
    const ConcurrentMdp mdp(acting(testing::random_instance(seed + 1700, 4, 3, 10)));
    const ConcurrentState start = mdp.start();
    const ChoiceList choices = mdp.refine_choices(start);
    for (const int choice : choices) {
      const int action = mdp.problem().action_at(choice, 0);
      std::vector<ConcurrentState> enumerated;
      mdp.for_each_step_outcome(start, choice,
                                [&](double, const ConcurrentState& next) { enumerated.push_back(next); });
      std::vector<ConcurrentState> observed;
      if (mdp.plan_first_mdp().hazard(action, 0) < 1.0) observed.push_back(mdp.step(start, choice, {}));
      if (mdp.plan_first_mdp().hazard(action, 0) > 0.0) {
        for (const Mdp::ExecutionOutcome& outcome : mdp.plan_first_mdp().execution_outcomes(action)) {
          // A time beyond the deadline is stored as D + 1, as the enumeration's "too slow".
          const Steps reported = outcome.steps > mdp.deadline() ? kNever : outcome.steps;
          observed.push_back(mdp.step(start, choice, Observation::found(reported)));
        }
      }
      EXPECT_EQ(observed, enumerated) << "seed " << seed << " choice " << choice;
    }
    EXPECT_THROW((void)mdp.step(start, ConcurrentMdp::kWait, Observation::found(1)), UsageError);
    EXPECT_THROW((void)mdp.step(start, choices[0], Observation::backtracked(0)), UsageError);
  }
}

TEST(ConcurrentAllocators, WithBacktrackingAnObservedStepIsTheModelsOutcome) {
  // Along random walks of instances that backtrack (SPEC §7): every observation a world may report
  // (not yet, a motion, a give-up naming each culprit) leads where the enumeration does, starts
  // made on the way so that culprits get executed too.
  int executed_culprits = 0;
  for (std::uint64_t seed = 0; seed < 60; ++seed) {
    const ConcurrentMdp mdp(acting(testing::with_backtracking(testing::random_instance(seed + 1900, 4, 3, 10), seed)));
    if (!mdp.has_backtracking()) continue;
    const Mdp& plan_first = mdp.plan_first_mdp();
    SplitMix64 generator(seed);
    ConcurrentState state = mdp.start();
    while (mdp.any_live(state) && ConcurrentMdp::time(state) < mdp.deadline()) {
      if (const std::optional<bool> started = maybe_start(mdp, state, generator)) {
        if (*started) continue;
        break;
      }
      const ChoiceList choices = mdp.refine_choices(state);
      if (choices.empty()) break;
      const int choice = choices[static_cast<std::size_t>(generator() % choices.size())];
      const int action = mdp.problem().action_at(choice, ConcurrentMdp::refined(state, choice));
      const Steps spent = mdp.spent(state, choice);
      std::vector<ConcurrentState> enumerated;
      mdp.for_each_step_outcome(state, choice,
                                [&](double, const ConcurrentState& next) { enumerated.push_back(next); });
      std::vector<ConcurrentState> observed;
      const double found = plan_first.hazard(action, spent);
      const double back = plan_first.backtrack_hazard(action, spent);
      if (found + back < 1.0) observed.push_back(mdp.step(state, choice, Observation::not_yet()));
      if (found > 0.0) {
        for (const Mdp::ExecutionOutcome& outcome : plan_first.execution_outcomes(action)) {
          observed.push_back(
              mdp.step(state, choice, Observation::found(outcome.steps > mdp.deadline() ? kNever : outcome.steps)));
        }
      }
      if (back > 0.0) {
        for (const Problem::CulpritIndex& culprit : mdp.problem().culprits(action)) {
          if (culprit.probability <= 0) continue;
          observed.push_back(mdp.step(state, choice, Observation::backtracked(culprit.action)));
          if (mdp.problem().position(culprit.action) < mdp.executed_depth(state)) ++executed_culprits;
        }
      }
      ASSERT_EQ(observed, enumerated) << "seed " << seed;
      state = enumerated[static_cast<std::size_t>(generator() % enumerated.size())];
    }
  }
  // The walks met give-ups that blame an executed motion (the rule of SPEC §10 for them).
  EXPECT_GT(executed_culprits, 0);
}

TEST(ConcurrentAllocators, WithBacktrackingEveryKindWithACommitRuleTakesIt) {
  const ConcurrentMdp mdp(acting(testing::with_backtracking(testing::random_instance(2, 4, 3, 10), 4)));
  ASSERT_TRUE(mdp.has_backtracking());
  for (const std::string name :
       {"optimal", "greedy", "round-robin", "first-found", "thompson", "mcts", "dp", "dp-rerun", "branch-and-bound"}) {
    const auto allocator = make_concurrent_allocator_factory(name, mdp)();
    EXPECT_EQ(allocator->name(), name);
  }
  // mcts's bound leaves value give-ups too (ConcurrentValueBounds).
  EXPECT_EQ(make_concurrent_allocator_factory("mcts", mdp, {{"backup", "bellman"}, {"leaf", "upper"}})()->name(),
            "mcts");
}

}  // namespace
}  // namespace ontime
