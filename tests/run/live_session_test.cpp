// Live sessions: deadlines in seconds on a clock, with the allocator's thinking, the planner's
// overruns and the caller's own time charged.

#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/dp_rerun.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "support/chain_reference.hpp"
#include "support/paper.hpp"
#include "support/sliced_world.hpp"

namespace ontime {
namespace {

// One skeleton a -> b; each action is found in 1 to 15 steps, uniformly, and executes in one.
Problem two_actions(Steps deadline, double step_seconds) {
  const auto action = [](std::string id) {
    std::vector<double> planning(16, 1.0 / 15);
    planning[0] = 0;
    return Action{std::move(id), Distribution::from_pmf(std::move(planning)), Distribution::from_pmf({0.0, 1.0})};
  };
  return Problem("two", deadline, step_seconds, {action("a"), action("b")}, {{0, 1}});
}

// A live dp-rerun session on a manual clock that starts at 0.
struct ManualLive {
  explicit ManualLive(Problem model) : problem(std::move(model)), mdp(problem), allocator(mdp) {}
  Problem problem;
  Mdp mdp;
  ManualClock clock;
  DpRerunAllocator allocator;
  Session session{mdp, allocator, 0, clock};
};

// Always skeleton 0; each decision takes `thinking` seconds of the manual clock. Records the
// MDP time of every state it is asked about.
class SlowAllocator final : public Allocator {
 public:
  SlowAllocator(ManualClock& clock, double thinking) : clock_(&clock), thinking_(thinking) {}
  std::string_view name() const noexcept override { return "slow"; }
  int choose(const State& state) override {
    seen_times.push_back(state.time);
    clock_->advance(thinking_);
    return 0;
  }
  std::vector<int> seen_times;

 private:
  ManualClock* clock_;
  double thinking_;
};

TEST(LiveSession, ASlowAllocatorLosesTheStepsItsThinkingConsumed) {
  const Problem problem = two_actions(20, 2.0);
  const Mdp mdp(problem);
  ManualClock clock(100.0);
  SlowAllocator allocator(clock, 0.4 * 2.0);  // 0.4 of a slice per decision
  Session session(mdp, allocator, 0, clock);
  for (int call = 0; call < 5; ++call) {
    ASSERT_EQ(session.choose().skeleton, 0);
    clock.advance(2.0);  // the planner uses exactly its slice
    ASSERT_EQ(session.report_not_yet(), Status::running);
  }
  // 5 slices of planning and 5 x 0.4 slices of thinking: 7 slices gone, not 5.
  EXPECT_NEAR(session.elapsed_seconds(), 14.0, 1e-9);
  EXPECT_EQ(session.steps_used(), 7);
  // Before decision k the clock read 1.4 (k - 1) slices: ceil gives 0, 2, 3, 5, 6.
  EXPECT_EQ(allocator.seen_times, (std::vector<int>{0, 2, 3, 5, 6}));
  EXPECT_NEAR(session.totals().decision, 5 * 0.8, 1e-12);
  EXPECT_NEAR(session.totals().planning, 10.0, 1e-12);
  ASSERT_EQ(session.timeline().size(), 5U);
  EXPECT_NEAR(session.timeline()[1].decision_seconds, 0.8, 1e-12);
  EXPECT_NEAR(session.timeline()[1].start, 2.8, 1e-12);
  // The planning effort on `a` is still one step per call.
  EXPECT_EQ(session.state().spent[0], 5);
}

TEST(LiveSession, APlannerOverrunOfTwoAndAHalfSlicesCostsThreeSteps) {
  ManualLive live(two_actions(20, 1.0));
  ManualClock& clock = live.clock;
  Session& session = live.session;
  session.choose();
  clock.advance(1.0 + 2.5);  // its slice, then 2.5 slices more
  EXPECT_EQ(session.report_not_yet(), Status::running);
  EXPECT_EQ(session.steps_used(), 1 + 3);
  const LiveStep& step = session.timeline().back();
  EXPECT_DOUBLE_EQ(step.overrun_seconds, 2.5);
  EXPECT_DOUBLE_EQ(step.planning_seconds, 3.5);
  EXPECT_EQ(step.steps_charged, 4);
  // The planner did three whole slices of work on `a` without finding it.
  EXPECT_EQ(session.state().spent[0], 3);

  // The same call within its slice costs one step.
  ManualClock exact_clock;
  Session exact(live.mdp, live.allocator, 0, exact_clock);
  exact.choose();
  exact_clock.advance(1.0);
  exact.report_not_yet();
  EXPECT_EQ(exact.steps_used(), 1);
  EXPECT_EQ(exact.state().spent[0], 1);
  EXPECT_DOUBLE_EQ(exact.timeline().back().overrun_seconds, 0.0);
}

// One action, found in one step: whether the session succeeds depends only on the seconds.
Status finish_with(double planning_seconds, double execution_seconds) {
  ManualLive live(Problem("one", 10, 1.0,
                          {Action{"a", Distribution::from_pmf({0.0, 1.0}), Distribution::from_pmf({0.0, 0.0, 1.0})}},
                          {{0}}));
  live.session.choose();
  live.clock.advance(planning_seconds);
  return live.session.report_refined_seconds(execution_seconds);
}

TEST(LiveSession, SuccessNeedsTheExecutionSecondsToFitInTheSecondsLeft) {
  EXPECT_EQ(finish_with(1.0, 9.0), Status::success);  // 1 + 9 = 10 s
  EXPECT_EQ(finish_with(1.0, 9.2), Status::failure);  // 10.2 s: too late, nothing else to try
  // Steps would round 0.5 s up to a step and 9.4 s up to 10 steps (11 > 10); the seconds fit.
  EXPECT_EQ(finish_with(0.5, 9.4), Status::success);
  EXPECT_EQ(finish_with(1.0, std::numeric_limits<double>::infinity()), Status::failure);
}

TEST(LiveSession, TheCallersOwnTimeIsCharged) {
  ManualLive live(two_actions(10, 1.0));
  ManualClock& clock = live.clock;
  Session& session = live.session;
  session.choose();
  clock.advance(1.0);
  session.report_not_yet();
  clock.advance(2.5);           // the caller was busy between the report and the next decision
  session.charge_outside(1.0);  // and spent a second the clock did not see
  EXPECT_DOUBLE_EQ(session.elapsed_seconds(), 4.5);
  session.choose();
  EXPECT_EQ(session.state().time, 5);
  EXPECT_DOUBLE_EQ(session.timeline().back().outside_seconds, 2.5);
  EXPECT_DOUBLE_EQ(session.totals().outside, 3.5);
  EXPECT_THROW(session.charge_outside(-1.0), UsageError);
}

TEST(LiveSession, ADeadlinePassedWhileTheCallerWasAwayEndsTheSession) {
  ManualLive live(two_actions(10, 1.0));
  ManualClock& clock = live.clock;
  Session& session = live.session;
  clock.advance(9.5);  // no skeleton can be refined and executed in the half second left
  const Decision decision = session.choose();
  EXPECT_EQ(decision.skeleton, -1);
  EXPECT_EQ(session.status(), Status::failure);
  EXPECT_DOUBLE_EQ(session.elapsed_seconds(), 9.5);
  clock.advance(5.0);
  EXPECT_DOUBLE_EQ(session.elapsed_seconds(), 9.5);  // frozen at the end
  EXPECT_THROW(session.choose(), std::logic_error);
}

TEST(LiveSession, AnAnytimeAllocatorGetsItsShareOfASlice) {
  const Problem problem = testing::paper_instance("instance1");
  SteadyClock clock;
  // Slices of 0.05 s: a quarter of one is 12.5 ms of search.
  const Problem fast(problem.name(), problem.deadline(), 0.05,
                     std::vector<Action>(problem.actions().begin(), problem.actions().end()), [&] {
                       std::vector<std::vector<int>> skeletons;
                       for (int k = 0; k < problem.skeleton_count(); ++k) {
                         skeletons.emplace_back(problem.skeleton(k).begin(), problem.skeleton(k).end());
                       }
                       return skeletons;
                     }());
  const Mdp fast_mdp(fast);
  auto searcher = make_allocator_factory("mcts", fast_mdp)();
  Session session(fast_mdp, *searcher, 1, clock, LiveOptions{.decision_share = 0.25});
  session.choose();
  const double thinking = session.timeline().back().decision_seconds;
  EXPECT_GE(thinking, 0.0125);
  EXPECT_LT(thinking, 0.0125 + 0.2);  // one iteration past the budget, on a loaded machine
  Statistics statistics;
  searcher->collect_statistics(statistics);
  EXPECT_GT(statistics.find("iterations").value_or(0), 1.0);
  EXPECT_THROW(Session(fast_mdp, *searcher, 1, clock, LiveOptions{.decision_share = 0.0}), UsageError);
}

using testing::SlicedWorld;

// The same episodes twice: in hidden worlds on the step clock (2 threads), then live in worlds
// whose every report takes exactly one slice (1 thread).
std::pair<MonteCarloResult, MonteCarloResult> model_and_live_episodes(const Problem& problem, const Mdp& mdp,
                                                                      const AllocatorFactory& factory,
                                                                      MonteCarloOptions options) {
  options.threads = 2;
  MonteCarloResult model = run_episodes(mdp, hidden_worlds(problem), factory, options);
  options.live = LiveRun{};
  options.threads = 1;
  MonteCarloResult live = run_episodes(
      mdp, [&problem] { return std::make_unique<SlicedWorld>(problem); }, factory, options);
  return {std::move(model), std::move(live)};
}

// With exact slices and no time elsewhere, a live session makes the MDP's transitions: the same
// episodes succeed.
TEST(LiveSession, ExactSlicesAndInstantDecisionsGiveTheModelsSuccesses) {
  for (const char* name : {"instance1", "instance2", "instance3", "instance4", "instance5"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    for (const char* solver : {"dp-rerun", "greedy", "round-robin", "thompson", "mcts"}) {
      SCOPED_TRACE(std::string(name) + " " + solver);
      const AllocatorFactory factory = make_allocator_factory(solver, mdp);
      MonteCarloOptions options;
      options.episodes = std::string_view(solver) == "mcts" ? 300 : 3000;
      // A live session would give mcts half a slice of real time per decision; the same
      // iterations in both runs make the same decisions.
      options.decision_budget = DecisionBudget::iterations(200);
      options.seed = 5;
      const auto [model, live] = model_and_live_episodes(problem, mdp, factory, options);
      EXPECT_EQ(live.successes, model.successes);
      EXPECT_EQ(live.model_successes, model.successes);
      EXPECT_EQ(live.model_undecided, 0U);
      EXPECT_DOUBLE_EQ(live.live_mean.decision, 0.0);
      EXPECT_DOUBLE_EQ(live.live_mean.overrun, 0.0);
      EXPECT_GT(live.live_mean.planning, 0.0);
    }
  }
}

// With exogenous chains (SPEC §9) a live session carried out in a world simulates the chains
// along its clock. On exact slices with instant decisions that is one chain step per report, as
// in the model: the same episodes succeed and earn the same rewards.
TEST(LiveSession, WithChainsExactSlicesAndInstantDecisionsGiveTheModelsEpisodes) {
  const Problem problem = load_problem(testing::source_path("data/instances/chains/meeting-through-the-queue.json"));
  const Mdp mdp(problem);
  for (const char* solver : {"optimal", "dp-rerun", "round-robin", "thompson"}) {
    SCOPED_TRACE(solver);
    const AllocatorFactory factory = make_allocator_factory(solver, mdp);
    MonteCarloOptions options;
    options.episodes = 2000;
    options.seed = 5;
    const auto [model, live] = model_and_live_episodes(problem, mdp, factory, options);
    EXPECT_GT(model.successes, 1000U);
    EXPECT_EQ(live.successes, model.successes);
    EXPECT_EQ(live.mean_reward, model.mean_reward);
    // The step clock's verdict is the plan completed in time; its execution in the chains is
    // drawn by the live session alone.
    EXPECT_GE(live.model_successes, live.successes);
  }
}

// A door open at even steps and a planner call that takes two slices: the chains still move once
// per step of the clock, so after each call (steps 2, 4 and 6) the door is open; one step of
// the chains per report would have it locked.
TEST(LiveSession, SimulatedChainsFollowTheClockAcrossLongCalls) {
  const Problem problem = testing::door_open_at_even_steps();
  SlicedWorld world(problem, 2);
  world.begin_episode(1);
  Session session(problem, Session::AllocatorMaker{}, 1, world.clock());
  for (const Steps time : {2, 4, 6}) {
    session.decide(1);  // the other skeleton: its planner never finds a motion
    EXPECT_EQ(session.carry_out(world), time < 6 ? Status::running : Status::failure);
    EXPECT_EQ(session.state().time, time);
    EXPECT_EQ(session.state().chains, 0) << "step " << time;  // open
  }
}

// A live session whose choices the caller makes, on exact slices: the transitions of the same
// choices in a session that is not live, the caller's decisions charged as taking no time.
TEST(LiveSession, CallerDecisionsOnExactSlicesMakeTheModelsTransitions) {
  const Problem problem = testing::paper_instance("instance2");
  const Mdp mdp(problem);
  int successes = 0;
  for (std::uint64_t episode = 0; episode < 200; ++episode) {
    SCOPED_TRACE("episode " + std::to_string(episode));
    SlicedWorld live_world(problem);
    HiddenWorld world(problem, 0);
    live_world.begin_episode(episode);
    world.begin_episode(episode);
    Session live(mdp, *live_world.clock());
    Session model(mdp);
    EXPECT_TRUE(live.is_live());
    EXPECT_FALSE(live.has_allocator());
    SplitMix64 random(episode);
    while (model.status() == Status::running) {
      const int choice = static_cast<int>(random() % static_cast<std::uint64_t>(mdp.skeleton_count()));
      const Decision decision = live.decide(choice);
      ASSERT_EQ(decision.skeleton, choice);
      EXPECT_EQ(decision.action, model.decide(choice).action);
      live.carry_out(live_world);
      model.carry_out(world);
      EXPECT_EQ(live.state(), model.state());
      EXPECT_EQ(live.status(), model.status());
    }
    EXPECT_EQ(live.solution(), model.solution());
    EXPECT_EQ(live.model_status(), model.status());
    EXPECT_EQ(live.timeline().size(), static_cast<std::size_t>(model.steps_used()));
    EXPECT_DOUBLE_EQ(live.totals().decision, 0.0);
    successes += model.status() == Status::success ? 1 : 0;
  }
  EXPECT_GT(successes, 0);
}

TEST(LiveSession, ACallerDecisionAfterTheDeadlinePassedEndsTheSession) {
  const Problem problem = two_actions(10, 0.5);
  const Mdp mdp(problem);
  ManualClock clock;
  Session session(mdp, clock);
  EXPECT_THROW(session.choose(), std::logic_error);  // no allocator
  EXPECT_THROW(session.decide(1), UsageError);       // one skeleton
  EXPECT_EQ(session.decide(0).action, 0);
  clock.advance(0.5);
  EXPECT_EQ(session.report_not_yet(), Status::running);
  clock.advance(5.0);  // the caller was away past the deadline
  EXPECT_EQ(session.decide(0).skeleton, -1);
  EXPECT_EQ(session.status(), Status::failure);
  EXPECT_THROW(session.decide(0), std::logic_error);
}

TEST(LiveSession, EpisodesKeepTheirTimelineWhenAsked) {
  const Problem problem = testing::paper_instance("instance2");
  const Mdp mdp(problem);
  DpRerunAllocator allocator(mdp);
  SlicedWorld world(problem);
  LiveRun live;
  live.keep_timeline = true;
  const EpisodeResult result = run_episode(mdp, allocator, world, 3, {}, nullptr, live);
  ASSERT_EQ(result.timeline.size(), static_cast<std::size_t>(result.decisions));
  double planning = 0;
  for (const LiveStep& step : result.timeline) {
    EXPECT_DOUBLE_EQ(step.planning_seconds, problem.step_seconds());
    EXPECT_EQ(step.steps_charged, 1);
    planning += step.planning_seconds;
  }
  EXPECT_DOUBLE_EQ(result.live.planning, planning);
  EXPECT_EQ(result.steps_used, result.decisions);
}

// A live session with exogenous chains (SPEC §9): move (2 s), then the coffee, whose wait is 1
// step with the queue short when it starts and 6 when long; deadline 6 steps of 1 s.
TEST(LiveSession, WithChainsTheReportsBringTheQueueAndThePlanIsWorthItsExpectedReward) {
  const Problem problem = parse_problem(R"({"deadline": 6, "step_seconds": 1.0,
      "chains": {"queue": {"states": ["short", "long"], "start": "short", "transitions": [[0.8, 0.2], [0.4, 0.6]]}},
      "actions": {"move": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"2": 1.0}}},
                  "coffee": {"planning": {"pmf": {"1": 1.0}},
                             "execution": {"chain": "queue", "by_state": {"short": {"pmf": {"1": 1.0}},
                                                                          "long": {"pmf": {"6": 1.0}}}}}},
      "skeletons": [["move", "coffee"]]})",
                                        "live-queue.json");
  const Mdp mdp(problem);
  for (const std::uint16_t queue : {std::uint16_t{0}, std::uint16_t{1}}) {
    ManualClock clock;
    Session session(problem, Session::AllocatorMaker{}, 1, &clock);
    ASSERT_EQ(session.decide(0).action, problem.find_action("move"));
    clock.advance(1.0);
    ASSERT_EQ(session.report_refined_seconds(2.0, 0), Status::running);
    ASSERT_EQ(session.decide(0).action, problem.find_action("coffee"));
    clock.advance(1.5);  // an overrun: the report comes 2.5 s in, and the third step is charged
    // The coffee's reported 30 s are not its wait (drawn when it starts): the plan's static part,
    // 2 s from 2.5 s in, fits in the 6 s.
    ASSERT_EQ(session.report_refined_seconds(30.0, queue), Status::success);
    EXPECT_EQ(session.state().time, 3);
    EXPECT_EQ(session.state().chains, queue);
    // The move runs in steps 3-4, the coffee starts at step 5 with the queue two steps on from
    // the reported state: short then (a 1-step wait, done at 6) wins, long (done at 11) loses.
    const double short_at_5 = queue == 0 ? 0.8 * 0.8 + 0.2 * 0.4 : 0.4 * 0.8 + 0.6 * 0.4;
    EXPECT_NEAR(session.reward(), short_at_5, 1e-15);
    EXPECT_EQ(session.reward(), mdp.execution_value(0, 3, queue, session.state().restore.data(), 2));
  }
}

}  // namespace
}  // namespace ontime
