// Streaming episodes: skeletons arrive from the world as a task planner finds them, on the
// documented schedule (one after every `period` steps, at once when none found can still
// succeed, up to `max_skeletons`), their search charged to a live episode's deadline, the same
// numbers for any thread count.

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/simulator.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

// Steps of effort certain to be `value`.
Distribution certain(Steps value) {
  std::vector<double> masses(static_cast<std::size_t>(value) + 1, 0.0);
  masses.back() = 1.0;
  return Distribution::from_pmf(masses);
}

// Execution quick (1 step) or hopeless (beyond `deadline`), even odds.
Distribution quick_or_hopeless(Steps deadline) {
  std::vector<double> masses(static_cast<std::size_t>(deadline) + 6, 0.0);
  masses[1] = 0.5;
  masses.back() = 0.5;
  return Distribution::from_pmf(masses);
}

// Streams the skeletons of a full problem in their order, answering steps from a hidden world of
// it; a live episode runs on a manual clock that each step advances by one slice.
class StreamedWorld final : public World {
 public:
  StreamedWorld(const Problem& full, double charged_slices)
      : full_(&full), hidden_(full, 0), charged_slices_(charged_slices) {}

  void begin_episode(std::uint64_t seed) override {
    hidden_.begin_episode(seed);
    next_ = 0;
    full_index_.clear();
  }
  Observation step(int action, Steps spent) override {
    clock_.advance(full_->step_seconds());
    return hidden_.step(full_index_.at(static_cast<std::size_t>(action)), spent);
  }
  const Clock* clock() const noexcept override { return &clock_; }
  std::optional<FoundSkeleton> next_skeleton() override {
    if (next_ >= full_->skeleton_count()) return std::nullopt;
    FoundSkeleton found;
    for (const int action : full_->skeleton(next_)) {
      found.action_ids.push_back(full_->action(action).id);
      if (std::find(full_index_.begin(), full_index_.end(), action) == full_index_.end()) {
        full_index_.push_back(action);
        found.new_actions.push_back(full_->action(action));
      }
    }
    found.charged_seconds = charged_slices_ * full_->step_seconds();
    ++next_;
    return found;
  }

 private:
  const Problem* full_;
  HiddenWorld hidden_;
  double charged_slices_;
  int next_ = 0;
  std::vector<int> full_index_;  // by the episode's action index
  ManualClock clock_;
};

StreamingRun streaming_of(const Problem& full, const std::string& allocator, int period, int max_skeletons) {
  StreamingRun run;
  run.name = full.name();
  run.deadline = full.deadline();
  run.step_seconds = full.step_seconds();
  run.period = period;
  run.max_skeletons = max_skeletons;
  run.make_allocator = [allocator](const Mdp& mdp) { return make_allocator_factory(allocator, mdp)(); };
  return run;
}

// Remembers how many skeletons each decision saw.
class CountingAllocator final : public Allocator {
 public:
  CountingAllocator(std::unique_ptr<Allocator> inner, int skeletons, std::vector<int>* seen)
      : inner_(std::move(inner)), skeletons_(skeletons), seen_(seen) {}
  std::string_view name() const noexcept override { return "counting"; }
  void begin_episode(std::uint64_t seed) override { inner_->begin_episode(seed); }
  int choose(const State& state) override { return choose(state, DecisionBudget{}); }
  int choose(const State& state, const DecisionBudget& budget) override {
    seen_->push_back(skeletons_);
    return inner_->choose(state, budget);
  }
  void observe(const State& before, int choice, const State& after, Status status) override {
    inner_->observe(before, choice, after, status);
  }

 private:
  std::unique_ptr<Allocator> inner_;
  int skeletons_;
  std::vector<int>* seen_;
};

TEST(StreamingEpisodes, SkeletonsArriveOneAfterEveryPeriodOfSteps) {
  const Problem full = testing::paper_instance("instance1");
  for (const int period : {1, 2, 3}) {
    std::vector<int> seen;
    StreamingRun run = streaming_of(full, "round-robin", period, full.skeleton_count());
    run.make_allocator = [&seen](const Mdp& mdp) -> std::unique_ptr<Allocator> {
      return std::make_unique<CountingAllocator>(make_allocator_factory("round-robin", mdp)(), mdp.skeleton_count(),
                                                 &seen);
    };
    StreamedWorld world(full, 0.0);
    const EpisodeResult result = run_streaming_episode(run, world, 7);
    ASSERT_GE(result.decisions, 1);
    ASSERT_EQ(seen.size(), static_cast<std::size_t>(result.decisions));
    // Decision i sees 1 + floor(i / period) skeletons (none dies this early on instance 1).
    const std::size_t checked = std::min<std::size_t>(seen.size(), static_cast<std::size_t>(period) * 3);
    for (std::size_t i = 0; i < checked; ++i) {
      EXPECT_EQ(seen[i], std::min(full.skeleton_count(), 1 + static_cast<int>(i) / period))
          << "period " << period << ", decision " << i;
    }
    EXPECT_LE(result.skeletons, full.skeleton_count());
  }
}

// Every action refined at its first step, with a scripted execution time.
class ScriptedWorld final : public World {
 public:
  struct Scripted {
    std::string id;
    Steps execution;
  };
  ScriptedWorld(std::vector<Scripted> skeletons, Steps deadline, double charged_slices)
      : skeletons_(std::move(skeletons)), deadline_(deadline), charged_slices_(charged_slices) {}
  void begin_episode(std::uint64_t) override { next_ = 0; }
  Observation step(int action, Steps) override {
    clock_.advance(1.0);
    return Observation::found(skeletons_.at(static_cast<std::size_t>(action)).execution);
  }
  const Clock* clock() const noexcept override { return &clock_; }
  std::optional<FoundSkeleton> next_skeleton() override {
    if (next_ >= skeletons_.size()) return std::nullopt;
    const Scripted& scripted = skeletons_[next_++];
    // The model allows a quick or a hopeless execution; the world decides.
    Action action{scripted.id, certain(1), quick_or_hopeless(deadline_)};
    FoundSkeleton found{{scripted.id}, {action}, charged_slices_};
    return found;
  }

 private:
  std::vector<Scripted> skeletons_;
  Steps deadline_;
  double charged_slices_;
  std::size_t next_ = 0;
  ManualClock clock_;
};

TEST(StreamingEpisodes, WhenNoSkeletonFoundCanSucceedTheNextIsTakenAtOnce) {
  const Steps deadline = 10;
  const std::vector<ScriptedWorld::Scripted> script{{"a", deadline + 5}, {"b", deadline + 5}, {"c", 1}};
  StreamingRun run;
  run.deadline = deadline;
  run.step_seconds = 1.0;
  run.period = 100;  // only a dead end brings the next one
  run.make_allocator = [](const Mdp& mdp) { return make_allocator_factory("dp-rerun", mdp)(); };
  {
    ScriptedWorld world(script, deadline, 0.0);
    const EpisodeResult result = run_streaming_episode(run, world, 1);
    EXPECT_EQ(result.status, Status::success);
    EXPECT_EQ(result.solution, 2);
    EXPECT_EQ(result.skeletons, 3);
    EXPECT_EQ(result.decisions, 3);
    EXPECT_EQ(result.steps_used, 3);
  }
  {
    run.max_skeletons = 2;  // the planner stops before the good one
    ScriptedWorld world(script, deadline, 0.0);
    const EpisodeResult result = run_streaming_episode(run, world, 1);
    EXPECT_EQ(result.status, Status::failure);
    EXPECT_EQ(result.skeletons, 2);
    EXPECT_EQ(result.decisions, 2);
  }
}

TEST(StreamingEpisodes, ALiveEpisodeIsChargedEverySearch) {
  const Steps deadline = 10;
  StreamingRun run;
  run.deadline = deadline;
  run.step_seconds = 1.0;
  run.period = 100;
  run.make_allocator = [](const Mdp& mdp) { return make_allocator_factory("dp-rerun", mdp)(); };
  ScriptedWorld world({{"a", deadline + 5}, {"b", deadline + 5}, {"c", 1}}, deadline, 0.25);
  const EpisodeResult result = run_streaming_episode(run, world, 1, {}, nullptr, LiveRun{{}, true});
  // 0.25 s of search, then per skeleton one 1 s step (the next search after each dead end):
  // 0.25 + 1 + 0.25 + 1 + 0.25 + 1 = 3.75 s, so CT = 4; c's motion takes 1 s more: in time.
  EXPECT_EQ(result.status, Status::success);
  EXPECT_EQ(result.solution, 2);
  EXPECT_DOUBLE_EQ(result.live.outside, 0.75);
  EXPECT_DOUBLE_EQ(result.live.elapsed, 3.75);
  EXPECT_EQ(result.steps_used, 4);
  ASSERT_NE(result.problem, nullptr);
  EXPECT_EQ(result.problem->skeleton_count(), 3);
  ASSERT_EQ(result.timeline.size(), 3U);
  EXPECT_DOUBLE_EQ(result.timeline[1].outside_seconds, 0.0);  // charged searches are not the caller's time
  EXPECT_DOUBLE_EQ(result.timeline[0].start, 0.25);
  EXPECT_DOUBLE_EQ(result.timeline[1].start, 1.5);
  EXPECT_DOUBLE_EQ(result.timeline[2].start, 2.75);
}

TEST(StreamingEpisodes, TheSameNumbersForAnyThreadCount) {
  const Problem full = testing::paper_instance("instance2");
  const StreamingRun run = streaming_of(full, "dp-rerun", 2, full.skeleton_count());
  const WorldFactory worlds = [&full] { return std::make_unique<StreamedWorld>(full, 0.0); };
  MonteCarloOptions options;
  options.episodes = 600;
  options.seed = 5;
  options.time_decisions = false;
  options.threads = 1;
  const MonteCarloResult one = run_streaming_episodes(run, worlds, options);
  options.threads = 2;
  const MonteCarloResult two = run_streaming_episodes(run, worlds, options);
  EXPECT_EQ(one.successes, two.successes);
  EXPECT_GT(one.successes, 0U);
  EXPECT_LT(one.successes, options.episodes);
}

TEST(StreamingEpisodes, ASessionExpectingMoreSkeletonsOutlivesItsDeadEnds) {
  const Steps deadline = 10;
  Problem problem("dead end", deadline, 1.0, {Action{"a", certain(1), quick_or_hopeless(deadline)}}, {{0}});
  Session session(
      problem, [](const Mdp& mdp) { return make_allocator_factory("dp-rerun", mdp)(); }, 1);
  session.expect_more_skeletons(true);
  session.choose();
  EXPECT_EQ(session.report_refined(deadline + 5), Status::running);
  EXPECT_FALSE(session.can_succeed());
  session.expect_more_skeletons(false);
  EXPECT_EQ(session.status(), Status::failure);

  const Mdp mdp(problem);
  auto allocator = make_allocator_factory("dp-rerun", mdp)();
  Session plain(mdp, *allocator);
  EXPECT_THROW(plain.expect_more_skeletons(true), std::logic_error);
}

}  // namespace
}  // namespace ontime
