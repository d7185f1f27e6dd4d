// Live sessions acting while planning (SPEC §10 on the robot's clock): on exact slices they make
// ConcurrentMdp's transitions; otherwise decisions, overruns and executions that end sooner or
// later are charged as docs/live.md says.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/concurrent_session.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"
#include "support/sliced_world.hpp"

namespace ontime {
namespace {

// a is found in 1 step and runs 2; b is found in 1 step or 4, evenly, and runs 1. Deadline 8
// steps of 2 seconds (16 s).
Problem two_timed_moves() {
  return parse_problem(R"({"deadline": 8, "step_seconds": 2, "acting": "concurrent",
    "actions": {"a": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"2": 1}}},
                "b": {"planning": {"pmf": {"1": 0.5, "4": 0.5}}, "execution": {"pmf": {"1": 1}}}},
    "skeletons": [["a", "b"]]})",
                       "two-moves");
}

// Each episode's status and reward, by episode.
struct Outcomes {
  std::vector<Status> status;
  std::vector<double> reward;
};

Outcomes concurrent_outcomes(const ConcurrentMdp& mdp, const WorldFactory& worlds,
                             const ConcurrentAllocatorFactory& factory, MonteCarloOptions options) {
  Outcomes outcomes;
  outcomes.status.assign(options.episodes, Status::running);
  outcomes.reward.assign(options.episodes, -1.0);
  options.on_episode = [&outcomes](std::uint64_t episode, const EpisodeResult& result) {
    outcomes.status[episode] = result.status;
    outcomes.reward[episode] = result.reward;
  };
  run_concurrent_episodes(mdp, worlds, factory, options);
  return outcomes;
}

// With a manual clock advanced by exactly one slice per planner step and nothing else, a live
// concurrent session makes ConcurrentMdp's transitions: the same episodes succeed, with the same
// rewards, as in the model's episodes. With exogenous chains and expiry (SPEC §9) too: the live
// session follows the chains along its clock and draws a chain-dependent execution at its start,
// as the model's does (the two small examples; the cup's has give-ups and rewards).
TEST(LiveConcurrentSession, ExactSlicesAndInstantDecisionsGiveTheModelsEpisodes) {
  std::vector<Problem> problems;
  for (const char* name : {"instance1", "instance2", "instance3", "instance4", "instance5"}) {
    problems.push_back(testing::paper_instance(name).with_acting(Acting::concurrent));
  }
  for (const char* name : {"meeting-through-the-queue", "cup-through-the-door"}) {
    problems.push_back(load_problem(testing::source_path(std::string("data/instances/chains/") + name + ".json"))
                           .with_acting(Acting::concurrent));
  }
  for (const Problem& problem : problems) {
    const ConcurrentMdp mdp(problem);
    for (const char* solver : {"dp-rerun", "greedy", "round-robin", "optimal"}) {
      SCOPED_TRACE(problem.name() + " " + solver);
      const ConcurrentAllocatorFactory factory = make_concurrent_allocator_factory(solver, mdp);
      MonteCarloOptions options;
      options.episodes = 2000;
      options.seed = 7;
      options.threads = 2;
      const Outcomes model = concurrent_outcomes(mdp, hidden_worlds(problem), factory, options);
      options.live = LiveRun{};
      options.threads = 1;
      const Outcomes live = concurrent_outcomes(
          mdp, [&problem] { return std::make_unique<testing::SlicedWorld>(problem); }, factory, options);
      EXPECT_EQ(live.status, model.status);
      EXPECT_EQ(live.reward, model.reward);
      std::size_t successes = 0;
      for (const Status status : model.status) successes += status == Status::success ? 1 : 0;
      EXPECT_GT(successes, 0U);
    }
  }
}

// An overrun of a slice and a half: CT jumps from 1 to 4, b's effort counts the two whole slices
// the call took, and the robot, whose motion ended meanwhile (at 5 s), is idle.
TEST(LiveConcurrentSession, APlannerOverrunCostsTheStepsItTookAndCountsAsEffort) {
  const Problem problem = two_timed_moves();
  const ConcurrentMdp mdp(problem);
  ManualClock clock;
  ConcurrentSession session(mdp, clock);
  EXPECT_EQ(session.decide({-1, 0}).action, 0);
  clock.advance(2);
  EXPECT_EQ(session.report_refined_seconds(3.0), Status::running);  // a: 3 s, 2 steps
  EXPECT_EQ(session.steps_used(), 1);
  EXPECT_TRUE(session.decide({0, ConcurrentMdp::kWait}).is_start());  // a runs from 2 s to 5 s
  EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 2);           // ceil(5 / 2) - 1
  EXPECT_EQ(session.decide({-1, 0}).action, 1);
  clock.advance(5);  // 2.5 slices
  EXPECT_EQ(session.report_not_yet(), Status::running);
  EXPECT_EQ(session.steps_used(), 4);  // ceil(7 / 2)
  EXPECT_EQ(mdp.spent(session.state(), 0), 2);
  EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 0);
  ASSERT_EQ(session.timeline().size(), 3U);
  const LiveStep& overrun = session.timeline()[2];
  EXPECT_DOUBLE_EQ(overrun.planning_seconds, 5.0);
  EXPECT_DOUBLE_EQ(overrun.overrun_seconds, 3.0);
  EXPECT_EQ(overrun.steps_charged, 3);
  EXPECT_EQ(session.timeline()[1].started, 0);
  EXPECT_EQ(session.attempts()[1].effort, 2);
  // b can still be found at its 4th step (CT 6), run to 7 <= 8.
  session.decide({-1, 0});
  clock.advance(2);
  EXPECT_EQ(session.report_not_yet(), Status::running);
  EXPECT_EQ(session.steps_used(), 5);
  session.decide({-1, 0});
  clock.advance(2);
  EXPECT_EQ(session.report_refined_seconds(1.5), Status::running);
  EXPECT_EQ(session.steps_used(), 6);
  session.decide({1, ConcurrentMdp::kWait});  // b from 11 s to 12.5 s
  EXPECT_EQ(session.status(), Status::success);
  EXPECT_DOUBLE_EQ(session.finish_seconds(), 12.5);
  EXPECT_DOUBLE_EQ(session.elapsed_seconds(), 11.0);
  const LiveTotals totals = session.totals();
  EXPECT_DOUBLE_EQ(totals.planning, 11.0);
  EXPECT_DOUBLE_EQ(totals.overrun, 3.0);
  EXPECT_DOUBLE_EQ(totals.decision, 0.0);
  EXPECT_EQ(session.executions(), (std::vector<LiveExecution>{{0, 2.0, 5.0}, {1, 11.0, 12.5}}));
}

// The session's executions against hand-computed ones (sums of tenths of a second on the clock are
// not exact in binary).
void expect_executions(const ConcurrentSession& session, const std::vector<LiveExecution>& expected) {
  ASSERT_EQ(session.executions().size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(session.executions()[i].action, expected[i].action) << i;
    EXPECT_NEAR(session.executions()[i].start, expected[i].start, 1e-12) << i;
    EXPECT_NEAR(session.executions()[i].end, expected[i].end, 1e-12) << i;
  }
}

// Starts the robot on a refined child of what it executed while it is idle, else refines
// skeleton 0; thinks `thinking` seconds of the manual clock per move and records the CT it saw.
class SlowEagerAllocator final : public ConcurrentAllocator {
 public:
  SlowEagerAllocator(const ConcurrentMdp& mdp, ManualClock& clock, double thinking)
      : mdp_(&mdp), clock_(&clock), thinking_(thinking) {}
  std::string_view name() const noexcept override { return "slow-eager"; }
  ConcurrentMdp::Move choose(const ConcurrentState& state) override {
    seen_times.push_back(ConcurrentMdp::time(state));
    clock_->advance(thinking_);
    const std::vector<int> startable = mdp_->startable(state);
    if (!startable.empty()) return {startable.front(), ConcurrentMdp::kWait};
    return {-1, 0};
  }
  std::vector<Steps> seen_times;

 private:
  const ConcurrentMdp* mdp_;
  ManualClock* clock_;
  double thinking_;
};

// Each move thinks 0.4 of a slice (0.8 s); planner steps take one slice. The robot starts a at
// 3.6 s (to 6.6 s) and b when the decision ends at 7.2 s (to 8.2 s).
TEST(LiveConcurrentSession, ASlowDecisionIsChargedAndDelaysTheStart) {
  const Problem problem = two_timed_moves();
  const ConcurrentMdp mdp(problem);
  ManualClock clock;
  SlowEagerAllocator allocator(mdp, clock, 0.8);
  ConcurrentSession session(mdp, allocator, 1, clock);
  EXPECT_EQ(session.choose().action, 0);
  clock.advance(2);
  EXPECT_EQ(session.report_refined_seconds(3.0), Status::running);
  EXPECT_EQ(session.steps_used(), 2);  // ceil(2.8 / 2)
  EXPECT_EQ(session.choose().start, 0);
  EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 2);  // ceil(6.6 / 2) - 2
  EXPECT_EQ(session.choose().action, 1);
  clock.advance(2);
  EXPECT_EQ(session.report_refined_seconds(1.0), Status::running);
  EXPECT_EQ(session.steps_used(), 4);  // ceil(6.4 / 2)
  EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 0);
  EXPECT_EQ(session.choose().start, 1);
  EXPECT_EQ(session.status(), Status::success);
  EXPECT_EQ(allocator.seen_times, (std::vector<Steps>{0, 2, 2, 4}));
  EXPECT_NEAR(session.totals().decision, 3.2, 1e-12);
  EXPECT_NEAR(session.finish_seconds(), 8.2, 1e-12);
  expect_executions(session, {{0, 3.6, 6.6}, {1, 7.2, 8.2}});
}

// a from 2 s (5 s by its motion), b refined at 4 s: the robot reports when a really ends.
ConcurrentSession started_and_refined_by_four_seconds(const ConcurrentMdp& mdp, ManualClock& clock) {
  ConcurrentSession session(mdp, clock);
  session.decide({-1, 0});
  clock.advance(2);
  session.report_refined_seconds(3.0);
  session.decide({0, ConcurrentMdp::kWait});
  session.decide({-1, 0});
  clock.advance(2);
  session.report_refined_seconds(1.0);
  return session;
}

TEST(LiveConcurrentSession, AnExecutionThatEndsSoonerFreesTheRobotAtOnce) {
  const ConcurrentMdp mdp(two_timed_moves());
  ManualClock clock;
  ConcurrentSession session = started_and_refined_by_four_seconds(mdp, clock);
  EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 1);  // ceil(5 / 2) - 2
  EXPECT_THROW(session.decide({1, ConcurrentMdp::kWait}), UsageError);
  EXPECT_EQ(session.report_execution_finished(0), Status::running);
  EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 0);
  session.decide({1, ConcurrentMdp::kWait});
  EXPECT_EQ(session.status(), Status::success);
  EXPECT_DOUBLE_EQ(session.finish_seconds(), 5.0);
  EXPECT_EQ(session.executions(), (std::vector<LiveExecution>{{0, 2.0, 4.0}, {1, 4.0, 5.0}}));
}

TEST(LiveConcurrentSession, AnExecutionThatEndsLaterHoldsTheRobotAndCanCostTheDeadline) {
  const ConcurrentMdp mdp(two_timed_moves());
  {
    ManualClock clock;
    ConcurrentSession session = started_and_refined_by_four_seconds(mdp, clock);
    EXPECT_EQ(session.report_execution_left(0, 3.0), Status::running);  // ends at 7 s
    EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 2);           // ceil(7 / 2) - 2
    EXPECT_THROW(session.decide({1, ConcurrentMdp::kWait}), UsageError);
    session.decide({-1, ConcurrentMdp::kWait});
    clock.advance(2);
    EXPECT_EQ(session.report_not_yet(), Status::running);
    EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 1);
    session.decide({-1, ConcurrentMdp::kWait});
    clock.advance(2);
    EXPECT_EQ(session.report_not_yet(), Status::running);
    EXPECT_EQ(session.steps_used(), 4);
    EXPECT_EQ(ConcurrentMdp::robot_left(session.state()), 0);
    session.decide({1, ConcurrentMdp::kWait});  // at 8 s: b to 9 s
    EXPECT_EQ(session.status(), Status::success);
    EXPECT_DOUBLE_EQ(session.finish_seconds(), 9.0);
    EXPECT_EQ(session.executions(), (std::vector<LiveExecution>{{0, 2.0, 7.0}, {1, 8.0, 9.0}}));
  }
  {
    // 20 s more: the robot is free at 24 s, past the 16 s deadline, so nothing can finish.
    ManualClock clock;
    ConcurrentSession session = started_and_refined_by_four_seconds(mdp, clock);
    EXPECT_EQ(session.report_execution_left(0, 20.0), Status::failure);
    EXPECT_DOUBLE_EQ(session.elapsed_seconds(), 4.0);
  }
  {
    ManualClock clock;
    ConcurrentSession session = started_and_refined_by_four_seconds(mdp, clock);
    EXPECT_THROW(session.report_execution_left(1, 1.0), UsageError);   // never started
    EXPECT_THROW(session.report_execution_left(0, -1.0), UsageError);  // time runs forwards
    const ConcurrentMdp::Move wait{-1, ConcurrentMdp::kWait};
    ConcurrentSession not_live(mdp);
    not_live.decide(wait);
    EXPECT_THROW(not_live.report_refined_seconds(1.0), std::logic_error);
  }
}

// The state rounds the seconds gone up to whole steps (CT = ceil(elapsed / step_seconds)), so a
// skeleton lives while CT + r and its executions fit in D steps. b refined, the robot idle: at 14 s
// (CT 7) b starts and ends at 15 s; at 14.5 s CT is 8, and b's step of execution no longer fits
// (it would end at 15.5 s, within the 16 s, but the step count says 9 > 8). Starts never end past
// the deadline in seconds: they begin by CT's seconds and run at most their whole steps.
TEST(LiveConcurrentSession, ALastMotionStartsOnlyWhileItsStepsFitTheDeadline) {
  const ConcurrentMdp mdp(two_timed_moves());
  for (const double away : {0.0, 0.5}) {
    ManualClock clock;
    ConcurrentSession session = started_and_refined_by_four_seconds(mdp, clock);
    session.report_execution_finished(0);
    session.decide({-1, ConcurrentMdp::kWait});
    clock.advance(10.0 + away);
    const Status status = session.report_not_yet();
    if (away > 0) {
      EXPECT_EQ(status, Status::failure);
      EXPECT_EQ(session.steps_used(), 8);
      continue;
    }
    EXPECT_EQ(session.steps_used(), 7);
    session.decide({1, ConcurrentMdp::kWait});
    EXPECT_EQ(session.status(), Status::success);
    EXPECT_DOUBLE_EQ(session.finish_seconds(), 15.0);
  }
}

// An owning session takes a skeleton as it arrives: the state carried over equals the state the
// same moves give on the final skeletons from the start; a skeleton not through what the robot
// executed arrives dropped, and retire_dropped removes it.
TEST(LiveConcurrentSession, ArrivingSkeletonsCarryTheStateOverAsIfTheyHadBeenThereFromTheStart) {
  const auto action = [](std::string id, std::vector<double> planning) {
    return Action{std::move(id), Distribution::from_pmf(std::move(planning)), Distribution::from_pmf({0.0, 0.0, 1.0})};
  };
  const std::vector<Action> actions{action("a", {0.0, 0.5, 0.5}), action("b", {0.0, 0.2, 0.8}),
                                    action("c", {0.0, 0.6, 0.4}), action("d", {0.0, 1.0})};
  const Problem first("arrivals", 10, 1.0, {actions[0], actions[1]}, {{0, 1}});
  const Problem full("arrivals", 10, 1.0, {actions[0], actions[1], actions[2]}, {{0, 1}, {0, 2}});
  const ConcurrentMdp full_mdp(full);
  for (const bool live : {false, true}) {
    SCOPED_TRACE(live ? "live" : "steps");
    ManualClock clock;
    ManualClock full_clock;
    ConcurrentSession growing(first, ConcurrentSession::AllocatorMaker{}, 1, live ? &clock : nullptr);
    ConcurrentSession from_start = live ? ConcurrentSession(full_mdp, full_clock) : ConcurrentSession(full_mdp);
    // a missed, then found (2 steps to execute), b missed: on both.
    for (ConcurrentSession* session : {&growing, &from_start}) {
      ManualClock& its_clock = session == &growing ? clock : full_clock;
      session->decide({-1, 0});
      its_clock.advance(1);
      session->report_not_yet();
      session->decide({-1, 0});
      its_clock.advance(1);
      session->report_refined(2);
      session->decide({-1, 0});
      its_clock.advance(1);
      session->report_not_yet();
    }
    EXPECT_EQ(growing.add_skeleton({"a", "c"}, {actions[2]}), 1);
    EXPECT_EQ(growing.state(), from_start.state());
    EXPECT_EQ(growing.problem().action_count(), 3);
    // The robot starts a; d does not go through it, so it arrives dropped and then retires.
    growing.decide({0, ConcurrentMdp::kWait});
    EXPECT_EQ(growing.add_skeleton({"d"}, {actions[3]}), 2);
    EXPECT_FALSE(ConcurrentMdp::is_live(growing.state(), 2));
    EXPECT_TRUE(ConcurrentMdp::is_live(growing.state(), 1));
    EXPECT_EQ(growing.retire_dropped(), 1);
    EXPECT_EQ(growing.problem().skeleton_count(), 2);
    EXPECT_EQ(growing.started(), std::vector<int>{0});
    EXPECT_EQ(ConcurrentMdp::robot_left(growing.state()), 2);
  }
  ConcurrentSession not_owning(full_mdp);
  EXPECT_THROW(not_owning.add_skeleton({"a"}), std::logic_error);
}

// A door open or closed at every step after the first w.p. 1/2 each; a is found at once and runs 2
// steps; b's execution is drawn from the door's state when it starts (1 step open, 3 closed); c
// (found in 1 or 2 steps, 1 to execute) cannot start while the door is closed (with `locked`, the
// door starts closed and stays so). Deadline 10 steps of 1 s.
Problem door_problem(bool with_c, bool locked = false) {
  std::string text =
      R"({"deadline": 10, "step_seconds": 1, "acting": "concurrent", "chains": {"door": {"states": ["open", "closed"], )";
  text += locked ? R"("start": "closed", "transitions": [[1, 0], [0, 1]]}},)"
                 : R"("start": "open", "transitions": [[0.5, 0.5], [0.5, 0.5]]}},)";
  text += R"("actions": {"a": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"2": 1}}},
    "b": {"planning": {"pmf": {"1": 1}},
          "execution": {"chain": "door", "by_state": {"open": {"pmf": {"1": 1}}, "closed": {"pmf": {"3": 1}}}}})";
  text += with_c ? R"(, "c": {"planning": {"pmf": {"1": 0.5, "2": 0.5}}, "execution": {"pmf": {"1": 1}},
          "expires": {"chain": "door", "states": ["closed"]}}}, "skeletons": [["a", "b"], ["a", "c"]]})"
                 : R"(}, "skeletons": [["a", "b"]]})";
  return parse_problem(text, "door");
}

// SPEC §9's chains follow a live session's clock: a call that takes three slices moves them three
// steps, as three steps on the model's clock do (the same seed, the same path), and so does a slow
// decision: the state before the move holds their state at its CT.
TEST(LiveConcurrentSession, TheChainsFollowTheClockHoweverManyStepsACallTakes) {
  const Problem problem = door_problem(true);
  const ConcurrentMdp mdp(problem);
  const ConcurrentMdp::Move wait{-1, ConcurrentMdp::kWait};
  std::vector<int> seen(2, 0);
  for (std::uint64_t seed = 1; seed <= 16; ++seed) {
    SCOPED_TRACE(seed);
    ManualClock clock;
    ConcurrentSession live(problem, ConcurrentSession::AllocatorMaker{}, seed, &clock);
    ConcurrentSession model(mdp, seed);
    // a is found in one slice and started at once on both.
    live.decide({-1, 0});
    model.decide({-1, 0});
    clock.advance(1);
    live.report_refined(2);
    model.report_refined(2);
    live.decide({0, ConcurrentMdp::kWait});
    model.decide({0, ConcurrentMdp::kWait});
    ASSERT_EQ(live.state(), model.state());
    // An idle call of three slices; three idle steps on the model's clock.
    live.decide(wait);
    clock.advance(3);
    live.report_not_yet();
    for (int step = 0; step < 3; ++step) {
      model.decide(wait);
      model.report_not_yet();
    }
    EXPECT_EQ(live.steps_used(), 4);
    EXPECT_EQ(live.state(), model.state());
    ++seen[ConcurrentMdp::chains(model.state())];
    // A decision that takes two slices: the move is made at CT 6.
    clock.advance(2);
    live.decide(wait);
    for (int step = 0; step < 2; ++step) {
      model.decide(wait);
      model.report_not_yet();
    }
    EXPECT_EQ(live.steps_used(), 6);
    EXPECT_EQ(ConcurrentMdp::chains(live.state()), ConcurrentMdp::chains(model.state()));
    ++seen[ConcurrentMdp::chains(model.state())];
  }
  // Both states of the door were met, so that the comparisons above could tell them apart.
  EXPECT_GT(seen[0], 0);
  EXPECT_GT(seen[1], 0);
}

// The moves of the streaming test below: start what the robot may start (a first, then c), else
// refine c (missed once, then found), else idle; the same on both sessions, which must agree.
void follow_the_door(ConcurrentSession& growing, ConcurrentSession& from_start, ManualClock* clock,
                     ManualClock* from_start_clock) {
  int attempts_on_c = 0;
  for (int move = 0; move < 40 && from_start.status() == Status::running; ++move) {
    ASSERT_EQ(growing.status(), Status::running);
    ASSERT_EQ(growing.state(), from_start.state());
    const ConcurrentMdp& mdp = from_start.mdp();
    const ConcurrentState& state = from_start.state();
    const std::vector<int> startable = mdp.startable(state);
    const auto may_start = [&](const char* id) {
      const int action = from_start.problem().find_action(id);
      return std::find(startable.begin(), startable.end(), action) != startable.end() ? action : -1;
    };
    ConcurrentMdp::Move chosen{-1, ConcurrentMdp::kWait};
    if (may_start("a") >= 0 || may_start("c") >= 0) {
      chosen = {std::max(may_start("a"), may_start("c")), ConcurrentMdp::kWait};
    } else if (ConcurrentMdp::is_live(state, 1) && ConcurrentMdp::refined(state, 1) < 2) {
      chosen = {-1, 1};
    } else if (may_start("b") >= 0) {
      chosen = {may_start("b"), ConcurrentMdp::kWait};
    }
    growing.decide(chosen);
    from_start.decide(chosen);
    if (chosen.is_start()) continue;
    if (clock != nullptr) clock->advance(1);
    if (from_start_clock != nullptr) from_start_clock->advance(1);
    const bool found = chosen.refine == 1 && ++attempts_on_c == 2;
    for (ConcurrentSession* session : {&growing, &from_start}) {
      if (found) {
        session->report_refined(1);
      } else {
        session->report_not_yet();
      }
    }
  }
  EXPECT_NE(from_start.status(), Status::running);
  EXPECT_EQ(growing.status(), from_start.status());
  EXPECT_EQ(growing.reward(), from_start.reward());
  EXPECT_EQ(growing.started(), from_start.started());
}

// Skeletons that stream in with exogenous chains (SPEC §9): a skeleton that arrives once a and b
// are refined finds the state it would have had from the start, the chains' state and b's
// execution to be drawn at its start included, and the episode goes on as if it had been there
// (the same moves, the same chains, the same end), on the model's steps and on the clock.
TEST(LiveConcurrentSession, SkeletonsThatStreamInCarryTheChainsOver) {
  const Problem first = door_problem(false);
  const Problem full = door_problem(true);
  const ConcurrentMdp full_mdp(full);
  const Action c = full.action(full.find_action("c"));
  std::vector<int> arrived_in(2, 0);  // the door's state when c arrived
  int successes = 0;
  for (const bool live : {false, true}) {
    for (std::uint64_t seed = 1; seed <= 12; ++seed) {
      SCOPED_TRACE(std::string(live ? "live" : "steps") + " seed " + std::to_string(seed));
      ManualClock clock;
      ManualClock full_clock;
      ConcurrentSession growing(first, ConcurrentSession::AllocatorMaker{}, seed, live ? &clock : nullptr);
      // On the model's steps the session from the start does not own its problem.
      ConcurrentSession from_start =
          live ? ConcurrentSession(full, ConcurrentSession::AllocatorMaker{}, seed, &full_clock)
               : ConcurrentSession(full_mdp, seed);
      // a found (2 steps), then b (its execution reported but drawn when it starts): on both.
      for (const Steps reported : {2, 5}) {
        growing.decide({-1, 0});
        from_start.decide({-1, 0});
        clock.advance(1);
        full_clock.advance(1);
        growing.report_refined(reported);
        from_start.report_refined(reported);
      }
      EXPECT_EQ(growing.add_skeleton({"a", "c"}, {c}), 1);
      EXPECT_EQ(full_mdp.execution(growing.state(), full.find_action("b")), ConcurrentMdp::kDrawnAtStart);
      ++arrived_in[ConcurrentMdp::chains(growing.state())];
      follow_the_door(growing, from_start, live ? &clock : nullptr, live ? &full_clock : nullptr);
      successes += from_start.status() == Status::success ? 1 : 0;
    }
  }
  EXPECT_GT(arrived_in[0], 0);
  EXPECT_GT(arrived_in[1], 0);
  EXPECT_GT(successes, 0);
}

// What a live session with chains did not expect is refused naming the rule: the report of an
// execution it never started, of one that is not the robot's current one, and a start the door
// blocks (SPEC §9: a locked door, so that c can never start).
TEST(LiveConcurrentSession, WithChainsAReportOrAStartItDidNotExpectIsRefusedNamingTheRule) {
  const Problem problem = door_problem(true, true);
  const ConcurrentMdp mdp(problem);
  ManualClock clock;
  ConcurrentSession session(mdp, clock);
  session.decide({-1, 1});  // a, shared by both skeletons
  clock.advance(1);
  session.report_refined(2);
  const auto refused = [](const auto& call, const std::string& rule) {
    try {
      call();
      ADD_FAILURE() << "not refused: " << rule;
    } catch (const UsageError& error) {
      EXPECT_NE(std::string(error.what()).find(rule), std::string::npos) << error.what();
    }
  };
  refused([&] { session.report_execution_finished(0); }, "was never started");
  session.decide({0, ConcurrentMdp::kWait});
  refused([&] { session.report_execution_left(1, 1.0); }, "was never started");
  session.decide({-1, 1});  // c
  clock.advance(1);
  session.report_refined(1);
  clock.advance(2);  // a ends at 3 s
  refused([&] { session.decide({2, ConcurrentMdp::kWait}); }, "it expires (SPEC §9)");
  EXPECT_EQ(session.status(), Status::running);
  EXPECT_EQ(session.started(), std::vector<int>{0});
}

}  // namespace
}  // namespace ontime
