// Skeletons that arrive and leave while a session runs: the state carries over exactly, every
// allocator decides on the new set, and a refused change leaves the session as it was.

#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

// Instance 1's actions with some of its skeletons, in the order given.
Problem with_skeletons(const Problem& full, const std::vector<int>& which) {
  std::vector<std::vector<int>> skeletons;
  for (const int k : which) skeletons.emplace_back(full.skeleton(k).begin(), full.skeleton(k).end());
  return Problem(full.name(), full.deadline(), full.step_seconds(),
                 std::vector<Action>(full.actions().begin(), full.actions().end()), std::move(skeletons));
}

std::vector<std::string> ids_of(const Problem& problem, int k) {
  std::vector<std::string> ids;
  for (const int action : problem.skeleton(k)) ids.push_back(problem.action(action).id);
  return ids;
}

Session::AllocatorMaker maker(std::string name) {
  return [name = std::move(name)](const Mdp& mdp) { return make_allocator_factory(name, mdp)(); };
}

// Plays `steps` steps of the session against `world`, recording each (action, observation).
void play(Session& session, HiddenWorld& world, int steps, std::vector<std::pair<int, Observation>>& history) {
  for (int i = 0; i < steps && session.status() == Status::running; ++i) {
    const Decision decision = session.choose();
    if (decision.action < 0) {
      session.report_not_yet();
      history.emplace_back(-1, Observation::not_yet());
      continue;
    }
    const Observation seen =
        world.step(decision.action, session.state().spent[static_cast<std::size_t>(decision.skeleton)]);
    history.emplace_back(decision.action, seen);
    session.report(seen);
  }
}

// The state the same planner calls lead to from the start of `problem` (each call on the lowest
// skeleton refining that action; an idle step on a skeleton with nothing left).
State replayed(const Problem& problem, const std::vector<std::pair<int, Observation>>& history) {
  const Mdp mdp(problem);
  State state = mdp.start();
  for (const auto& [action, observation] : history) {
    int choice = -1;
    for (int k = 0; k < mdp.skeleton_count() && choice < 0; ++k) {
      if (action < 0 ? mdp.next_action(state, k) < 0 : mdp.next_action(state, k) == action) choice = k;
    }
    if (choice < 0) ADD_FAILURE() << "no skeleton refines action " << action;
    if (choice < 0) return state;
    mdp.apply(state, choice, observation);
  }
  return state;
}

TEST(ChangingSkeletons, AnArrivingSkeletonStartsFromWhatWasLearntAndEveryExactAllocatorAgreesWithAFreshOne) {
  const Problem full = testing::paper_instance("instance1");
  ASSERT_GE(full.skeleton_count(), 3);
  for (const char* name :
       {"optimal", "dp", "dp-rerun", "greedy", "round-robin", "first-found", "found-order-round-robin"}) {
    SCOPED_TRACE(name);
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      Session session(with_skeletons(full, {0, 1}), maker(name), seed);
      HiddenWorld world(full, seed);
      std::vector<std::pair<int, Observation>> history;
      play(session, world, 2, history);
      if (session.status() != Status::running) continue;
      const int added = session.add_skeleton(ids_of(full, 2));
      EXPECT_EQ(added, 2);
      const Problem expected_problem = with_skeletons(full, {0, 1, 2});
      ASSERT_EQ(session.problem().skeleton_count(), 3);
      EXPECT_EQ(session.state(), replayed(expected_problem, history)) << "seed " << seed;
      if (session.status() != Status::running) continue;

      const Mdp fresh_mdp(expected_problem);
      auto fresh = make_allocator_factory(name, fresh_mdp)();
      fresh->begin_episode(0);
      EXPECT_EQ(session.choose().skeleton, fresh->choose(session.state())) << "seed " << seed;
      if (std::string_view(name) == "optimal") {
        OptimalSolver in_session(session.mdp());
        OptimalSolver from_scratch(fresh_mdp);
        EXPECT_DOUBLE_EQ(in_session.solve(session.state()), from_scratch.solve(replayed(expected_problem, history)));
      }
    }
  }
}

// `full`'s actions, chains and rewards with some of its skeletons, in the order given.
Problem with_chain_skeletons(const Problem& full, const std::vector<int>& which) {
  std::vector<std::vector<int>> skeletons;
  std::vector<SkeletonReward> rewards;
  for (const int k : which) {
    skeletons.emplace_back(full.skeleton(k).begin(), full.skeleton(k).end());
    rewards.push_back(full.reward(k));
  }
  return Problem(full.name(), full.deadline(), full.step_seconds(),
                 std::vector<Action>(full.actions().begin(), full.actions().end()), std::move(skeletons),
                 full.description(), std::move(rewards),
                 std::vector<ExogenousChain>(full.chains().begin(), full.chains().end()));
}

// With chains and expiry (SPEC §9) the carried state holds the chains' joint state and the static
// execution before each refined timed action, as if the skeleton had been there from the start.
TEST(ChangingSkeletons, WithChainsTheStateCarriesTheChainsAndTheExecutionsBeforeTimedActions) {
  int compared = 0;
  for (std::uint64_t seed = 1; seed <= 400; ++seed) {
    const Problem full =
        testing::with_random_chains(testing::random_instance(seed + 300, 5, 3, 9), seed + 300, seed % 2 == 0);
    if (full.skeleton_count() < 3) continue;
    Session session(with_chain_skeletons(full, {0, 1}), maker("round-robin"), seed);
    const Mdp full_mdp(full);
    HiddenWorld world(full, seed);
    SplitMix64 chains(seed);
    std::vector<std::pair<int, Observation>> history;
    for (int i = 0; i < 6 && session.status() == Status::running; ++i) {
      const Decision decision = session.choose();
      Observation seen =
          decision.action < 0
              ? Observation::not_yet()
              : world.step(decision.action, session.state().spent[static_cast<std::size_t>(decision.skeleton)]);
      seen = seen.with_chains(full_mdp.sample_chain_step(session.state().chains, chains));
      history.emplace_back(decision.action, seen);
      session.report(seen);
    }
    if (session.status() != Status::running) continue;
    session.add_skeleton(ids_of(full, 2), {}, full.reward(2));
    const Problem expected_problem = with_chain_skeletons(full, {0, 1, 2});
    const State expected = replayed(expected_problem, history);
    EXPECT_EQ(session.state(), expected) << "seed " << seed;
    ++compared;
    if (session.status() != Status::running) continue;
    OptimalSolver in_session(session.mdp());
    const Mdp fresh_mdp(expected_problem);
    OptimalSolver from_scratch(fresh_mdp);
    EXPECT_EQ(in_session.solve(session.state()), from_scratch.solve(expected)) << "seed " << seed;
  }
  EXPECT_GT(compared, 10);
}

// move (2 steps of execution), then the coffee (its wait depends on the queue, drawn when it
// starts), then the meeting (`meet`: its fields); a second way on from the coffee arrives once it
// is refined. Returns the state carried over, checked against the replay of the same history.
State arrival_behind_the_coffee(const std::string& meet) {
  const Problem full = parse_problem(R"({"deadline": 30,
      "chains": {"queue": {"states": ["short", "long"], "start": "long", "transitions": [[0.5, 0.5], [0.5, 0.5]]}},
      "actions": {"move": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"2": 1.0}}},
                  "coffee": {"planning": {"pmf": {"1": 1.0}},
                             "execution": {"chain": "queue", "by_state": {"short": {"pmf": {"1": 1.0}},
                                                                          "long": {"pmf": {"6": 1.0}}}}},
                  "meet": {)" + meet + R"(, "execution": {"pmf": {"1": 1.0}}},
                  "call": {"planning": {"pmf": {"3": 1.0}}, "execution": {"pmf": {"1": 1.0}}}},
      "skeletons": [["move", "coffee", "meet"], ["move", "coffee", "call"]]})",
                                     "coffee.json");
  Session session(with_chain_skeletons(full, {0}), Session::AllocatorMaker{}, 1);
  const int move = full.find_action("move");
  const int coffee = full.find_action("coffee");
  // Step 1 finds the move (queue short after it), step 2 the coffee (queue long after it); the
  // coffee's reported 5 steps are not its wait, which is drawn when it starts.
  std::vector<std::pair<int, Observation>> history{{move, Observation::found(2).with_chains(0)},
                                                   {coffee, Observation::found(5).with_chains(1)}};
  for (const auto& [action, observation] : history) {
    EXPECT_EQ(session.decide(0).action, session.problem().find_action(full.action(action).id));
    session.report(observation);
  }
  EXPECT_EQ(session.status(), Status::running);
  session.add_skeleton(ids_of(full, 1), {}, full.reward(1));
  const State carried = session.state();
  EXPECT_EQ(carried.time, 2);
  EXPECT_EQ(carried.chains, 1);        // long
  EXPECT_EQ(carried.refined[1], 2);    // move and coffee
  EXPECT_EQ(carried.execution[1], 2);  // the move's; the coffee's wait is drawn when it starts
  EXPECT_EQ(carried.restore[static_cast<std::size_t>(full.timed_slot(coffee))], 2);  // the execution before it
  EXPECT_EQ(carried, replayed(full, history));
  return carried;
}

TEST(ChangingSkeletons, ASkeletonArrivingBehindARefinedTimedActionFindsItsExecutionBefore) {
  arrival_behind_the_coffee(R"("planning": {"pmf": {"4": 1.0}})");
}

// With backtracking too (SPEC §7 with §9): the coffee, timed, is also the culprit the meeting may
// blame, and the state carried over holds its execution before it in both slots.
TEST(ChangingSkeletons, ASkeletonArrivingBehindATimedCulpritFindsBothItsSlots) {
  const State carried = arrival_behind_the_coffee(
      R"("planning": {"pmf": {"4": 0.5}}, "backtrack": {"pmf": {"2": 0.5}}, "culprits": {"coffee": 1.0})");
  EXPECT_EQ(carried.restore[0], 2);  // the culprit slot; the timed one, 1, is checked above
}

TEST(ChangingSkeletons, ARetiredSkeletonLeavesTheOthersAsTheyWere) {
  const Problem full = testing::paper_instance("instance1");
  Session session(with_skeletons(full, {0, 1, 2}), maker("dp-rerun"), 3);
  HiddenWorld world(full, 3);
  std::vector<std::pair<int, Observation>> history;
  play(session, world, 2, history);
  ASSERT_EQ(session.status(), Status::running);
  const State before = session.state();
  session.retire_skeleton(0);
  ASSERT_EQ(session.problem().skeleton_count(), 2);
  EXPECT_EQ(std::vector<int>(session.problem().skeleton(0).begin(), session.problem().skeleton(0).end()),
            std::vector<int>(full.skeleton(1).begin(), full.skeleton(1).end()));
  EXPECT_EQ(session.state().time, before.time);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(session.state().refined[k], before.refined[k + 1]);
    EXPECT_EQ(session.state().spent[k], before.spent[k + 1]);
    EXPECT_EQ(session.state().execution[k], before.execution[k + 1]);
  }
  session.retire_skeleton(1);
  session.retire_skeleton(0);  // the last one: nothing is left
  EXPECT_EQ(session.status(), Status::failure);
}

TEST(ChangingSkeletons, NewActionsJoinBehindAKnownPrefix) {
  const Problem full = testing::paper_instance("instance1");
  Session session(with_skeletons(full, {0}), maker("dp-rerun"), 1);
  const std::string first = full.action(full.skeleton(0)[0]).id;
  // The planner finds the first action at once, with a 2-step motion.
  const Decision decision = session.choose();
  ASSERT_EQ(decision.action, full.skeleton(0)[0]);
  session.report_refined(2);
  ASSERT_EQ(session.status(), Status::running);
  const int added = session.add_skeleton({first, "detour"}, {Action{"detour", Distribution::from_pmf({0.0, 0.5, 0.5}),
                                                                    Distribution::from_pmf({0.0, 1.0})}});
  EXPECT_EQ(added, 1);
  EXPECT_EQ(session.problem().action_count(), full.action_count() + 1);
  EXPECT_EQ(session.state().refined[1], 1);
  EXPECT_EQ(session.state().execution[1], 2);
  EXPECT_EQ(session.state().spent[1], 0);
  EXPECT_EQ(session.mdp().next_action(session.state(), 1), session.problem().find_action("detour"));
}

TEST(ChangingSkeletons, ARefusedChangeLeavesTheSessionAsItWas) {
  const Problem full = testing::paper_instance("instance1");
  Session session(with_skeletons(full, {0, 1}), maker("dp-rerun"), 1);
  const State before = session.state();
  EXPECT_THROW(session.add_skeleton({"no-such-action"}), UsageError);
  EXPECT_THROW(session.add_skeleton(ids_of(full, 0)), UsageError);  // listed twice
  EXPECT_THROW(session.retire_skeleton(2), UsageError);
  EXPECT_EQ(session.problem().skeleton_count(), 2);
  EXPECT_EQ(session.state(), before);
  session.choose();
  EXPECT_THROW(session.add_skeleton(ids_of(full, 2)), std::logic_error);  // a decision awaits its report
  session.report_not_yet();
  EXPECT_NO_THROW(session.add_skeleton(ids_of(full, 2)));

  // An allocator that cannot take the new problem: the maker's error, nothing changed.
  int made = 0;
  Session picky(
      with_skeletons(full, {0, 1}),
      [&made](const Mdp& mdp) -> std::unique_ptr<Allocator> {
        if (++made > 1) throw UsageError("this allocator takes one problem only");
        return make_allocator_factory("greedy", mdp)();
      },
      1);
  EXPECT_THROW(picky.add_skeleton(ids_of(full, 2)), UsageError);
  EXPECT_EQ(picky.problem().skeleton_count(), 2);

  // A session over a caller's Mdp cannot change it.
  const Mdp mdp(full);
  auto allocator = make_allocator_factory("greedy", mdp)();
  Session fixed(mdp, *allocator);
  EXPECT_THROW(fixed.add_skeleton(ids_of(full, 2)), std::logic_error);
}

// Randomised allocators and searches through arrivals and retirements, to the end of each
// episode; the same seed gives the same episode.
TEST(ChangingSkeletons, EveryAllocatorPlaysThroughArrivalsAndRetirements) {
  const Problem full = testing::paper_instance("instance1");
  for (const char* name : {"mcts", "thompson", "dp", "dp-rerun", "greedy", "round-robin", "first-found",
                           "found-order-round-robin", "optimal"}) {
    SCOPED_TRACE(name);
    const auto episode = [&](std::uint64_t seed) {
      Session session(
          with_skeletons(full, {1}),
          [name](const Mdp& mdp) {
            ParameterValues values;
            if (std::string_view(name) == "mcts") values.set("iterations", "300");
            return make_allocator_factory(name, mdp, values)();
          },
          seed);
      HiddenWorld world(full, seed);
      std::vector<std::pair<int, Observation>> history;
      play(session, world, 1, history);
      if (session.status() == Status::running) session.add_skeleton(ids_of(full, 0));
      play(session, world, 1, history);
      if (session.status() == Status::running) session.add_skeleton(ids_of(full, 2));
      play(session, world, 1, history);
      if (session.status() == Status::running && session.problem().skeleton_count() == 3) session.retire_skeleton(0);
      play(session, world, 1000, history);
      EXPECT_NE(session.status(), Status::running);
      return std::make_pair(session.status(), history.size());
    };
    int successes = 0;
    for (std::uint64_t seed = 1; seed <= 30; ++seed) {
      const auto first = episode(seed);
      EXPECT_EQ(episode(seed), first) << "seed " << seed;
      successes += first.first == Status::success ? 1 : 0;
    }
    EXPECT_GT(successes, 0);
  }
}

// Revised distributions (an online belief's posterior): the state stays, every action takes the
// belief's distributions (a node "x#2" its base's), and the allocator decides as a fresh one made
// for the revised problem; a belief that lacks an action changes nothing.
TEST(ChangingSkeletons, RevisedDistributionsKeepTheStateAndTheAllocatorPlansWithThem) {
  const Problem full = testing::paper_instance("instance1");
  // The belief: every action's planning distribution that of the action after it (cyclically).
  std::vector<Action> shifted(full.actions().begin(), full.actions().end());
  for (std::size_t a = 0; a < shifted.size(); ++a) {
    shifted[a].planning = full.action(static_cast<int>((a + 1) % shifted.size())).planning;
  }
  const Problem belief(full.name(), full.deadline(), full.step_seconds(), shifted, {{0}});
  for (const char* name : {"optimal", "dp-rerun", "greedy"}) {
    SCOPED_TRACE(name);
    for (std::uint64_t seed = 1; seed <= 10; ++seed) {
      Session session(with_skeletons(full, {0, 1, 2}), maker(name), seed);
      HiddenWorld world(full, seed);
      std::vector<std::pair<int, Observation>> history;
      play(session, world, 2, history);
      if (session.status() != Status::running) continue;
      const State before = session.state();
      session.revise_distributions(belief);
      EXPECT_EQ(session.state(), before);
      for (int a = 0; a < full.action_count(); ++a) {
        EXPECT_EQ(session.problem().action(a).planning, belief.action(a).planning) << a;
        EXPECT_EQ(session.problem().action(a).execution, full.action(a).execution) << a;
      }
      if (session.status() != Status::running) continue;
      const Problem revised = with_distributions_of(with_skeletons(full, {0, 1, 2}), belief);
      const Mdp fresh_mdp(revised);
      auto fresh = make_allocator_factory(name, fresh_mdp)();
      fresh->begin_episode(0);
      EXPECT_EQ(session.choose().skeleton, fresh->choose(session.state())) << "seed " << seed;
    }
  }
  // A belief without some action: refused, nothing changed.
  Session session(with_skeletons(full, {0, 1}), maker("dp-rerun"), 1);
  const Problem partial(full.name(), full.deadline(), full.step_seconds(), {full.action(0)}, {{0}});
  EXPECT_THROW(session.revise_distributions(partial), UsageError);
  EXPECT_EQ(session.problem().action(1).planning, full.action(1).planning);
  // Only a session that owns its problem can revise it.
  const Mdp mdp(full);
  auto allocator = make_allocator_factory("greedy", mdp)();
  Session fixed(mdp, *allocator);
  EXPECT_THROW(fixed.revise_distributions(full), std::logic_error);
}

// Each action's attempt as the session saw it: a step of effort per call in the model; on the
// clock, the slices its calls were charged (as PT_k counts them).
TEST(ChangingSkeletons, TheSessionRecordsEachActionsAttempt) {
  const Problem full = testing::paper_instance("instance1");
  ManualClock clock;
  Session session(with_skeletons(full, {0}), nullptr, 1, &clock);
  const int first = full.skeleton(0)[0];
  session.decide(0);
  clock.advance(full.step_seconds() * 2.5);  // an overrun: 2 slices of effort
  session.report_not_yet();
  EXPECT_EQ(session.attempts()[static_cast<std::size_t>(first)].effort, 2);
  EXPECT_FALSE(session.attempts()[static_cast<std::size_t>(first)].found);
  session.decide(0);
  clock.advance(full.step_seconds());
  session.report_refined(1);
  EXPECT_EQ(session.attempts()[static_cast<std::size_t>(first)].effort, 3);
  EXPECT_TRUE(session.attempts()[static_cast<std::size_t>(first)].found);
  EXPECT_EQ(session.state().spent[0], 0);
}

TEST(ChangingSkeletons, ALiveSessionKeepsItsClockAcrossChanges) {
  const Problem full = testing::paper_instance("instance1");
  ManualClock clock;
  Session session(with_skeletons(full, {0}), maker("dp-rerun"), 1, &clock);
  session.choose();
  clock.advance(full.step_seconds() * 2.5);
  session.report_not_yet();
  const Steps time = session.state().time;
  EXPECT_EQ(time, 3);
  session.add_skeleton(ids_of(full, 1));
  EXPECT_EQ(session.state().time, time);
  EXPECT_DOUBLE_EQ(session.elapsed_seconds(), full.step_seconds() * 2.5);
  EXPECT_EQ(session.timeline().size(), 1U);
}

}  // namespace
}  // namespace ontime
