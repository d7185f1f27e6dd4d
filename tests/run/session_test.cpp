#include "ontime/run/session.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "ontime/allocators/optimal.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

// An allocator that replays a script and records what it observed.
class ScriptedAllocator final : public Allocator {
 public:
  explicit ScriptedAllocator(std::vector<int> script) : script_(std::move(script)) {}
  std::string_view name() const noexcept override { return "scripted"; }
  void begin_episode(std::uint64_t) override { ++episodes; }
  int choose(const State&) override { return script_.at(next_++); }
  void observe(const State&, int choice, const State& after, Status status) override {
    observed.push_back(choice);
    last_time = after.time;
    last_status = status;
  }
  bool is_stationary() const noexcept override { return false; }

  int episodes = 0;
  std::vector<int> observed;
  int last_time = -1;
  Status last_status = Status::running;

 private:
  std::vector<int> script_;
  std::size_t next_ = 0;
};

TEST(Session, DrivesTheOptimalPolicyOfFigureOneToSuccess) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  OptimalAllocator optimal(mdp);
  Session session(mdp, optimal);
  // The planner finds d1 in one step with a fast motion; d12's motion is slow; d22's is fast.
  Decision decision = session.choose();
  EXPECT_EQ(decision.skeleton, 0);
  EXPECT_EQ(problem.action(decision.action).id, "d1");
  EXPECT_EQ(session.report_refined(1), Status::running);
  decision = session.choose();
  EXPECT_EQ(problem.action(decision.action).id, "d12");
  EXPECT_EQ(session.report_refined(10), Status::running);
  decision = session.choose();
  EXPECT_EQ(problem.action(decision.action).id, "d22");
  EXPECT_EQ(session.report_refined(1), Status::success);
  EXPECT_EQ(session.solution(), 1);
  EXPECT_EQ(session.steps_used(), 3);
  EXPECT_THROW(session.choose(), std::logic_error);
}

TEST(Session, ReportsFailureAsSoonAsTheDeadlineIsOutOfReach) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  ScriptedAllocator allocator({0, 0, 0});
  Session session(mdp, allocator);
  EXPECT_EQ(allocator.episodes, 1);
  session.choose();
  EXPECT_EQ(session.report_not_yet(), Status::running);
  session.choose();
  EXPECT_EQ(session.report_not_yet(), Status::failure);  // nothing can fit in the 3 steps left
  EXPECT_EQ(session.solution(), -1);
  EXPECT_EQ(allocator.observed, (std::vector<int>{0, 0}));
  EXPECT_EQ(allocator.last_time, 2);
  EXPECT_EQ(allocator.last_status, Status::failure);
}

TEST(Session, RejectsMisuse) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  ScriptedAllocator allocator({0, 0, 7});
  Session session(mdp, allocator);
  EXPECT_THROW(session.report_not_yet(), std::logic_error);  // no decision yet
  session.choose();
  EXPECT_THROW(session.choose(), std::logic_error);  // decision not reported
  EXPECT_THROW(session.report_refined(-3), UsageError);
  EXPECT_EQ(session.report_refined(1), Status::running);
  session.choose();
  EXPECT_EQ(session.report_refined(10), Status::running);
  EXPECT_THROW(session.choose(), UsageError);  // allocator answered skeleton 7
}

TEST(Session, IdleStepsCannotReportARefinement) {
  const Problem problem(
      "idle", 6, 1.0,
      {Action{"a", Distribution::from_pmf({0.0, 1.0}), Distribution::from_pmf({0, 0, 0, 0, 0, 0, 1.0})},
       Action{"b", Distribution::from_pmf({0.0, 0.0, 1.0}), Distribution::from_pmf({1.0})}},
      {{0}, {1}});
  const Mdp mdp(problem);
  ScriptedAllocator allocator({0, 0});
  Session session(mdp, allocator);
  session.choose();
  EXPECT_EQ(session.report_refined(6), Status::running);  // too slow to execute
  const Decision idle = session.choose();
  EXPECT_EQ(idle.action, -1);
  EXPECT_THROW(session.report_refined(1), UsageError);
  EXPECT_EQ(session.report_not_yet(), Status::running);
}

// Any skeleton at random from the episode's stream (idle ones and hopeless ones too), recording
// every choice and the state after it.
class RandomRecordingAllocator final : public Allocator {
 public:
  explicit RandomRecordingAllocator(int skeletons) : skeletons_(static_cast<std::uint64_t>(skeletons)) {}
  std::string_view name() const noexcept override { return "random-recording"; }
  void begin_episode(std::uint64_t seed) override {
    random_ = SplitMix64(seed);
    choices.clear();
    states.clear();
  }
  int choose(const State&) override { return static_cast<int>(random_() % skeletons_); }
  void observe(const State&, int choice, const State& after, Status) override {
    choices.push_back(choice);
    states.push_back(after);
  }
  bool is_stationary() const noexcept override { return false; }

  std::vector<int> choices;
  std::vector<State> states;

 private:
  std::uint64_t skeletons_;
  SplitMix64 random_{0};
};

// A world that counts the steps it is asked for and finds every action at once, executing in no
// time.
class CountingWorld final : public World {
 public:
  void begin_episode(std::uint64_t) override {}
  Observation step(int, Steps) override {
    ++steps;
    return Observation::found(0);
  }
  int steps = 0;
};

// The caller's choices, carried out in the same hidden world, give the episode the allocator's
// choices gave in the episode runner: the same states step by step, the same end.
TEST(Session, ACallerDecidedSessionReplaysTheRunnersEpisode) {
  int idle_steps = 0;
  for (std::uint64_t instance = 0; instance < 40; ++instance) {
    const Problem problem = testing::random_instance(instance);
    const Mdp mdp(problem);
    RandomRecordingAllocator allocator(mdp.skeleton_count());
    HiddenWorld runner_world(problem, 0);
    for (std::uint64_t episode = 0; episode < 25; ++episode) {
      SCOPED_TRACE("instance " + std::to_string(instance) + " episode " + std::to_string(episode));
      const std::uint64_t seed = stream_seed(instance, episode);
      const EpisodeResult result = run_episode(mdp, allocator, runner_world, seed);
      ASSERT_EQ(allocator.choices.size(), static_cast<std::size_t>(result.decisions));

      HiddenWorld world(problem, seed);
      Session session(mdp);
      EXPECT_FALSE(session.has_allocator());
      for (std::size_t step = 0; step < allocator.choices.size(); ++step) {
        ASSERT_EQ(session.status(), Status::running);
        const int choice = allocator.choices[step];
        const Decision decision = session.decide(choice);
        EXPECT_EQ(decision.skeleton, choice);
        EXPECT_EQ(decision.action, mdp.next_action(session.state(), choice));
        if (decision.action < 0) ++idle_steps;
        session.carry_out(world);
        EXPECT_EQ(session.state(), allocator.states[step]);
      }
      EXPECT_EQ(session.status(), result.status);
      EXPECT_EQ(session.solution(), result.solution);
      EXPECT_EQ(session.steps_used(), result.steps_used);
    }
  }
  EXPECT_GT(idle_steps, 0);  // the replays met idle steps too
}

TEST(Session, CarryingOutAnIdleStepNeverAsksTheWorld) {
  const Problem problem(
      "idle", 6, 1.0,
      {Action{"a", Distribution::from_pmf({0.0, 1.0}), Distribution::from_pmf({0, 0, 0, 0, 0, 0, 1.0})},
       Action{"b", Distribution::from_pmf({0.0, 0.0, 1.0}), Distribution::from_pmf({1.0})}},
      {{0}, {1}});
  const Mdp mdp(problem);
  Session session(mdp);
  CountingWorld world;
  session.decide(0);
  EXPECT_EQ(session.report_refined(6), Status::running);  // too slow to execute: 0 is idle now
  EXPECT_EQ(session.decide(0).action, -1);
  EXPECT_EQ(session.carry_out(world), Status::running);
  EXPECT_EQ(world.steps, 0);
  EXPECT_EQ(session.steps_used(), 2);
  EXPECT_EQ(session.decide(1).action, 1);
  EXPECT_EQ(session.carry_out(world), Status::success);  // the counting world finds b at once
  EXPECT_EQ(world.steps, 1);
  EXPECT_EQ(session.solution(), 1);
}

TEST(Session, CallerDecisionsAreCheckedAsAllocatorsAre) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  Session session(mdp);
  CountingWorld world;
  EXPECT_THROW(session.choose(), std::logic_error);          // no allocator: the caller decides
  EXPECT_THROW(session.carry_out(world), std::logic_error);  // nothing decided yet
  EXPECT_THROW(session.report_not_yet(), std::logic_error);
  EXPECT_THROW(session.decide(-1), UsageError);
  EXPECT_THROW(session.decide(mdp.skeleton_count()), UsageError);
  session.decide(0);
  EXPECT_THROW(session.decide(0), std::logic_error);  // the decision waits for its report
  EXPECT_THROW(session.choose(), std::logic_error);
  EXPECT_EQ(session.report_not_yet(), Status::running);
  session.decide(0);
  EXPECT_EQ(session.report_not_yet(), Status::failure);  // nothing can fit in the 3 steps left
  EXPECT_THROW(session.decide(0), std::logic_error);     // over
  EXPECT_THROW(session.carry_out(world), std::logic_error);
  EXPECT_EQ(world.steps, 0);

  ScriptedAllocator allocator({0});
  Session driven(mdp, allocator);
  EXPECT_TRUE(driven.has_allocator());
  EXPECT_THROW(driven.decide(0), std::logic_error);  // the allocator decides
  EXPECT_EQ(driven.choose().skeleton, 0);
  EXPECT_EQ(driven.carry_out(world), Status::running);  // d1 found; d12 is still to come
  EXPECT_EQ(world.steps, 1);
}

// A session that owns its problem and has no allocator: skeletons arrive while the caller decides.
TEST(Session, ACallerDecidedSessionCanOwnItsProblem) {
  const auto action = [](std::string id, std::vector<double> planning) {
    return Action{std::move(id), Distribution::from_pmf(std::move(planning)), Distribution::from_pmf({1.0})};
  };
  Session session(Problem("owned", 6, 1.0, {action("a", {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0})}, {{0}}), {}, 0);
  EXPECT_FALSE(session.has_allocator());
  session.expect_more_skeletons(true);  // a can never be found in time, but more may come
  EXPECT_EQ(session.status(), Status::running);
  session.decide(0);
  EXPECT_EQ(session.report_not_yet(), Status::running);
  EXPECT_EQ(session.add_skeleton({"b"}, {action("b", {0.0, 1.0})}), 1);
  EXPECT_EQ(session.state().time, 1);
  EXPECT_EQ(session.decide(1).action, 1);
  EXPECT_EQ(session.report_refined(0), Status::success);
  EXPECT_EQ(session.solution(), 1);
}

// Backtracking (SPEC §7) in data/instances/backtracking/grasp-and-place.json: pick(A) (index 0) is
// found at its first step; place(A,R2) (2, of skeleton 1) gets one step; place(A,R1) (1, of
// skeleton 0) gets one step, then backtracks at its second, blaming pick(A). That ends three
// attempts: pick(A)'s (found after 1 step; its motion is discarded), place(A,R1)'s (backtracked
// after 2) and place(A,R2)'s (cut off after 1: it is below pick(A)); pick(B)'s (3) is not below the
// culprit and goes on. pick(A) is then found anew after 2 steps.
std::vector<ActionAttempt> grasp_and_place_attempts(Session& session, ManualClock* clock) {
  const auto step = [&](int skeleton, const Observation& observation) {
    session.decide(skeleton);
    if (clock != nullptr) clock->advance(session.problem().step_seconds());
    session.report(observation);
  };
  step(0, Observation::found(1));
  step(1, Observation::not_yet());
  step(0, Observation::not_yet());
  step(2, Observation::not_yet());
  step(0, Observation::backtracked(0));
  step(0, Observation::not_yet());
  step(0, Observation::found(1));
  return session.attempts();
}

TEST(Session, ABacktrackEndsTheAttemptsOfTheCulpritAndOfEveryActionBelowIt) {
  const Problem problem = load_problem(testing::source_path("data/instances/backtracking/grasp-and-place.json"));
  ASSERT_EQ(problem.find_action("place(A,R1)"), 1);
  ASSERT_EQ(problem.find_action("pick(B)"), 3);
  const Mdp mdp(problem);
  Session session(mdp);
  const std::vector<ActionAttempt> expected{
      ActionAttempt{2, true, {EndedAttempt{1, true, false}}},    // pick(A): found again after 2 steps
      ActionAttempt{0, false, {EndedAttempt{2, false, true}}},   // place(A,R1): backtracked after 2
      ActionAttempt{0, false, {EndedAttempt{1, false, false}}},  // place(A,R2): cut off after 1
      ActionAttempt{1, false},                                   // pick(B): going on
      ActionAttempt{0, false}};                                  // place(B,R1): never picked
  EXPECT_EQ(grasp_and_place_attempts(session, nullptr), expected);
  EXPECT_EQ(session.state().time, 7);
  // A live session whose clock moves one slice per call sees the same attempts.
  ManualClock clock;
  Session live(problem, {}, 0, &clock);
  EXPECT_EQ(grasp_and_place_attempts(live, &clock), expected);
}

}  // namespace
}  // namespace ontime
