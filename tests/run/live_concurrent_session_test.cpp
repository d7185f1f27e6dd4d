// Live sessions acting while planning (SPEC §10 on the robot's clock): on exact slices they make
// ConcurrentMdp's transitions; otherwise decisions, overruns and executions that end sooner or
// later are charged as docs/live.md says.

#include <gtest/gtest.h>

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
// rewards, as in the model's episodes.
TEST(LiveConcurrentSession, ExactSlicesAndInstantDecisionsGiveTheModelsEpisodes) {
  for (const char* name : {"instance1", "instance2", "instance3", "instance4", "instance5"}) {
    const Problem problem = testing::paper_instance(name).with_acting(Acting::concurrent);
    const ConcurrentMdp mdp(problem);
    for (const char* solver : {"dp-rerun", "greedy", "round-robin", "optimal"}) {
      SCOPED_TRACE(std::string(name) + " " + solver);
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

}  // namespace
}  // namespace ontime
