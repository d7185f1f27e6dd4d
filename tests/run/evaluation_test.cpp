#include "ontime/run/evaluation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <mutex>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/run/world.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

// Chooses uniformly at random: not stationary, so it cannot be evaluated exactly.
class RandomAllocator final : public Allocator {
 public:
  explicit RandomAllocator(int skeletons) : skeletons_(skeletons) {}
  std::string_view name() const noexcept override { return "random"; }
  int choose(const State&) override { return static_cast<int>(generator_() % static_cast<std::uint64_t>(skeletons_)); }
  bool is_stationary() const noexcept override { return false; }

 private:
  int skeletons_;
  SplitMix64 generator_{5};
};

// Sampled rates against exact values, over the five instances and four allocators: each
// deviation is measured in standard errors of the exact p. A correct simulator lands within
// 1.96 of them about 95% of the time and within 4 essentially always.
TEST(Evaluation, MonteCarloAgreesWithExactEvaluation) {
  constexpr std::uint64_t kEpisodes = 20'000;
  int cases = 0, inside = 0;
  for (int i = 1; i <= 5; ++i) {
    const Problem problem = testing::paper_instance("instance" + std::to_string(i));
    const Mdp mdp(problem);
    for (const char* name : {"dp", "dp-rerun", "greedy", "round-robin", "optimal"}) {
      const AllocatorFactory factory = make_allocator_factory(name, mdp);
      const auto allocator = factory();
      const double exact = evaluate_exactly(mdp, *allocator).success_probability;
      MonteCarloOptions options;
      options.episodes = kEpisodes;
      options.seed = 1000 + static_cast<std::uint64_t>(i);
      const MonteCarloResult sampled = run_monte_carlo(mdp, factory, options);
      const double standard_error = std::sqrt(exact * (1 - exact) / kEpisodes);
      const double deviation = std::abs(sampled.success_rate - exact);
      if (standard_error == 0) {
        EXPECT_EQ(sampled.success_rate, exact) << name << " instance" << i;
        continue;
      }
      ++cases;
      inside += deviation <= 1.96 * standard_error;
      EXPECT_LE(deviation, 4.0 * standard_error)
          << name << " instance" << i << ": " << sampled.success_rate << " vs " << exact;
    }
  }
  // At least 19 of 25 within 1.96 standard errors (a binomial(25, 0.95) falls below that with
  // probability < 0.2%).
  EXPECT_GE(inside, cases - 6) << inside << " of " << cases;
}

TEST(Evaluation, ResultsDoNotDependOnTheThreadCount) {
  const Problem problem = testing::paper_instance("instance3");
  const Mdp mdp(problem);
  const AllocatorFactory factory = make_allocator_factory("dp-rerun", mdp);
  MonteCarloOptions options;
  options.episodes = 5'000;
  options.seed = 77;
  options.threads = 1;
  const MonteCarloResult one = run_monte_carlo(mdp, factory, options);
  for (const unsigned threads : {2U, 3U, 8U}) {
    options.threads = threads;
    const MonteCarloResult many = run_monte_carlo(mdp, factory, options);
    EXPECT_EQ(many.successes, one.successes) << threads;
    EXPECT_EQ(many.decision_time.decisions, one.decision_time.decisions) << threads;
  }
  options.seed = 78;
  EXPECT_NE(run_monte_carlo(mdp, factory, options).successes, one.successes);
}

TEST(Evaluation, ConfidenceIntervalFollowsSpec) {
  EXPECT_DOUBLE_EQ(ci95_half_width(0.5, 100), 1.96 * 0.05);
  EXPECT_DOUBLE_EQ(ci95_half_width(1.0, 100), 0.0);
  const Problem problem = testing::paper_instance("instance2");
  const Mdp mdp(problem);
  MonteCarloOptions options;
  options.episodes = 1'000;
  const MonteCarloResult result = run_monte_carlo(mdp, make_allocator_factory("greedy", mdp), options);
  EXPECT_DOUBLE_EQ(result.success_rate, static_cast<double>(result.successes) / 1000.0);
  EXPECT_DOUBLE_EQ(result.ci95, ci95_half_width(result.success_rate, 1000));
  EXPECT_GT(result.decision_time.decisions, 1000U);
  EXPECT_LE(result.decision_time.median_us, result.decision_time.p99_us);
}

TEST(Evaluation, EveryAllocatorMeetsTheSameHiddenWorld) {
  const Problem problem = testing::paper_instance("instance1");
  const HiddenWorld first(problem, 123), second(problem, 123), other(problem, 124);
  bool differs = false;
  for (int a = 0; a < problem.action_count(); ++a) {
    EXPECT_EQ(first.planning_time(a), second.planning_time(a));
    EXPECT_EQ(first.execution_time(a), second.execution_time(a));
    differs = differs || first.planning_time(a) != other.planning_time(a);
  }
  EXPECT_TRUE(differs);
  // Effort on an action finds it exactly at its hidden planning time.
  const int action = 0;
  const Steps truth = first.planning_time(action);
  for (Steps spent = 0; spent < truth - 1; ++spent) EXPECT_FALSE(first.observe(action, spent).refined);
  EXPECT_TRUE(first.observe(action, truth - 1).refined);
}

TEST(Evaluation, ExactEvaluationNeedsAStationaryAllocator) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  RandomAllocator random(3);
  EXPECT_THROW(evaluate_exactly(mdp, random), UsageError);
  MonteCarloOptions options;
  options.episodes = 200;
  const MonteCarloResult sampled = run_monte_carlo(
      mdp, [] { return std::make_unique<RandomAllocator>(3); }, options);
  EXPECT_LE(sampled.success_rate, 0.5625 + 4 * std::sqrt(0.25 / 200));
}

TEST(Evaluation, ExactEvaluationStopsAtItsCap) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  const auto allocator = make_allocator_factory("round-robin", mdp)();
  EXPECT_THROW(evaluate_exactly(mdp, *allocator, 10), ResourceLimitError);
}

TEST(Evaluation, ErrorsInsideWorkersReachTheCaller) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  MonteCarloOptions options;
  options.episodes = 1'000;
  options.threads = 2;
  const AllocatorFactory broken = [] { return std::make_unique<RandomAllocator>(9); };  // out of range
  EXPECT_THROW(run_monte_carlo(mdp, broken, options), UsageError);
}

// A world of the test's own: each step on an action finds a motion with probability 1/4,
// executed in 0 to 2 steps, all drawn from the episode's seed, the action and the step.
class CoinWorld final : public World {
 public:
  void begin_episode(std::uint64_t seed) override {
    seed_ = seed;
    ++episodes_;
  }
  Observation step(int action, Steps spent) override {
    ++steps_;
    SplitMix64 generator(
        stream_seed(stream_seed(seed_, static_cast<std::uint64_t>(action)), static_cast<std::uint64_t>(spent)));
    if (generator() % 4 != 0) return Observation::not_yet();
    return Observation::found(static_cast<Steps>(generator() % 3));
  }
  void collect_statistics(Statistics& statistics) const override {
    statistics.add("episodes", static_cast<double>(episodes_));
    statistics.add("steps", static_cast<double>(steps_));
  }

 private:
  std::uint64_t seed_ = 0;
  std::uint64_t episodes_ = 0;
  std::uint64_t steps_ = 0;
};

// Chooses uniformly at random from the seed of each episode, and counts its decisions.
class SeededRandomAllocator final : public Allocator {
 public:
  explicit SeededRandomAllocator(int skeletons) : skeletons_(skeletons) {}
  std::string_view name() const noexcept override { return "seeded-random"; }
  void begin_episode(std::uint64_t seed) override { generator_ = SplitMix64(seed); }
  int choose(const State&) override {
    ++decisions_;
    return static_cast<int>(generator_() % static_cast<std::uint64_t>(skeletons_));
  }
  bool is_stationary() const noexcept override { return false; }
  void collect_statistics(Statistics& statistics) const override {
    statistics.add("decisions", static_cast<double>(decisions_));
  }

 private:
  int skeletons_;
  SplitMix64 generator_{0};
  std::uint64_t decisions_ = 0;
};

TEST(EpisodeRunner, AWorldOfTheCallersOwnGivesTheSameResultsOnOneAndTwoThreads) {
  const Problem problem = testing::paper_instance("instance3");
  const Mdp mdp(problem);
  const WorldFactory worlds = [] { return std::make_unique<CoinWorld>(); };
  const int skeletons = mdp.skeleton_count();
  const AllocatorFactory allocators = [skeletons] { return std::make_unique<SeededRandomAllocator>(skeletons); };
  MonteCarloOptions options;
  options.episodes = 3'000;
  options.seed = 11;
  options.threads = 1;
  const MonteCarloResult one = run_episodes(mdp, worlds, allocators, options);
  options.threads = 2;
  const MonteCarloResult two = run_episodes(mdp, worlds, allocators, options);

  EXPECT_GT(one.successes, 0U);
  EXPECT_LT(one.successes, options.episodes);
  EXPECT_EQ(two.successes, one.successes);
  EXPECT_EQ(two.decision_time.decisions, one.decision_time.decisions);
  EXPECT_EQ(one.world_statistics.find("episodes"), 3'000.0);
  EXPECT_EQ(two.world_statistics.find("episodes"), 3'000.0);
  EXPECT_EQ(two.world_statistics.find("steps"), one.world_statistics.find("steps"));
  EXPECT_GT(one.world_statistics.find("steps").value_or(0), 3'000.0);
  // Every decision reached the allocator; the world saw those that were not idle.
  EXPECT_EQ(one.statistics.find("decisions"), static_cast<double>(one.decision_time.decisions));
  EXPECT_EQ(two.statistics.find("decisions"), static_cast<double>(one.decision_time.decisions));
  EXPECT_LE(one.world_statistics.find("steps").value_or(0), static_cast<double>(one.decision_time.decisions));
  options.seed = 12;
  EXPECT_NE(run_episodes(mdp, worlds, allocators, options).successes, one.successes);
}

// Records the seeds its episodes begin with.
class SeedRecorder final : public Allocator {
 public:
  explicit SeedRecorder(std::vector<std::uint64_t>& seeds) : seeds_(&seeds) {}
  std::string_view name() const noexcept override { return "seed-recorder"; }
  void begin_episode(std::uint64_t seed) override { seeds_->push_back(seed); }
  int choose(const State&) override { return 0; }

 private:
  std::vector<std::uint64_t>* seeds_;
};

class SeedRecordingWorld final : public World {
 public:
  explicit SeedRecordingWorld(std::vector<std::uint64_t>& seeds) : seeds_(&seeds) {}
  void begin_episode(std::uint64_t seed) override { seeds_->push_back(seed); }
  Observation step(int, Steps) override { return Observation::not_yet(); }

 private:
  std::vector<std::uint64_t>* seeds_;
};

TEST(EpisodeRunner, EpisodeEHasItsOwnSeedForTheWorldAndAnotherStreamForTheAllocator) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  std::vector<std::uint64_t> world_seeds, allocator_seeds;
  MonteCarloOptions options;
  options.episodes = 3;
  options.seed = 42;
  options.threads = 1;
  run_episodes(
      mdp, [&] { return std::make_unique<SeedRecordingWorld>(world_seeds); },
      [&] { return std::make_unique<SeedRecorder>(allocator_seeds); }, options);
  ASSERT_EQ(world_seeds.size(), 3U);
  ASSERT_EQ(allocator_seeds.size(), 3U);
  for (std::uint64_t e = 0; e < 3; ++e) {
    EXPECT_EQ(world_seeds[e], stream_seed(42, e));
    EXPECT_EQ(allocator_seeds[e], stream_seed(stream_seed(42, e), 1));
  }
}

// Episodes in sequences: each sequence's episodes run in order on one thread, before_episode sees
// the thread's own world just before each, and the seeds and results stay those of the episodes'
// indices (the same successes as a run without sequences, for any thread count).
TEST(EpisodeRunner, SequencesRunInOrderOnOneThreadWithTheSameSeedsAndResults) {
  const Problem problem = testing::paper_instance("instance3");
  const Mdp mdp(problem);
  const AllocatorFactory factory = make_allocator_factory("dp-rerun", mdp);
  const WorldFactory worlds = [&problem] { return std::make_unique<HiddenWorld>(problem, 0); };
  MonteCarloOptions options;
  options.episodes = 600;
  options.seed = 5;
  options.threads = 1;
  std::vector<std::uint8_t> plain(600, 0);
  options.on_episode = [&](std::uint64_t episode, const EpisodeResult& result) {
    plain[episode] = result.status == Status::success ? 1 : 0;
  };
  const MonteCarloResult independent = run_episodes(mdp, worlds, factory, options);

  for (const unsigned threads : {1U, 2U, 3U}) {
    SCOPED_TRACE(threads);
    options.threads = threads;
    options.sequence_length = 20;
    std::vector<std::uint8_t> sequenced(600, 0);
    std::vector<std::uint64_t> last(30, 0);  // per sequence: the next episode expected
    std::vector<const World*> world_of(30, nullptr);
    std::mutex mutex;
    bool in_order = true, one_world = true;
    options.before_episode = [&](std::uint64_t episode, World& world) {
      const std::lock_guard lock(mutex);
      const std::uint64_t sequence = episode / 20;
      in_order = in_order && episode == sequence * 20 + last[sequence];
      ++last[sequence];
      if (world_of[sequence] == nullptr) world_of[sequence] = &world;
      one_world = one_world && world_of[sequence] == &world;
    };
    options.on_episode = [&](std::uint64_t episode, const EpisodeResult& result) {
      sequenced[episode] = result.status == Status::success ? 1 : 0;
    };
    const MonteCarloResult run = run_episodes(mdp, worlds, factory, options);
    EXPECT_TRUE(in_order);
    EXPECT_TRUE(one_world);
    EXPECT_EQ(last, std::vector<std::uint64_t>(30, 20));
    EXPECT_EQ(run.successes, independent.successes);
    EXPECT_EQ(sequenced, plain);
  }
  options.sequence_length = 7;  // 600 episodes are no whole number of sequences of 7
  EXPECT_THROW(run_episodes(mdp, worlds, factory, options), UsageError);
  options.sequence_length = 0;
  EXPECT_THROW(run_episodes(mdp, worlds, factory, options), UsageError);
}

// Decides as dp-rerun does, and counts the decisions that came with a budget of 7 iterations.
class BudgetRecorder final : public Allocator {
 public:
  explicit BudgetRecorder(std::unique_ptr<Allocator> inner) : inner_(std::move(inner)) {}
  std::string_view name() const noexcept override { return "budget-recorder"; }
  int choose(const State& state) override { return inner_->choose(state); }
  int choose(const State& state, const DecisionBudget& budget) override {
    ++decisions_;
    if (budget.max_iterations() == 7U) ++seven_iterations_;
    return inner_->choose(state, budget);
  }
  void collect_statistics(Statistics& statistics) const override {
    statistics.add("decisions", static_cast<double>(decisions_));
    statistics.add("with seven iterations", static_cast<double>(seven_iterations_));
  }

 private:
  std::unique_ptr<Allocator> inner_;
  std::uint64_t decisions_ = 0, seven_iterations_ = 0;
};

TEST(EpisodeRunner, ThePerDecisionBudgetReachesTheAllocator) {
  const Problem problem = testing::paper_instance("instance2");
  const Mdp mdp(problem);
  const AllocatorFactory dp_rerun = make_allocator_factory("dp-rerun", mdp);
  const AllocatorFactory recording = [&] { return std::make_unique<BudgetRecorder>(dp_rerun()); };
  MonteCarloOptions options;
  options.episodes = 500;
  options.threads = 2;
  const MonteCarloResult unset = run_monte_carlo(mdp, recording, options);
  EXPECT_EQ(unset.statistics.find("decisions"), static_cast<double>(unset.decision_time.decisions));
  EXPECT_EQ(unset.statistics.find("with seven iterations"), 0.0);

  options.decision_budget = DecisionBudget::iterations(7);
  const MonteCarloResult budgeted = run_monte_carlo(mdp, recording, options);
  EXPECT_GT(budgeted.decision_time.decisions, 500U);
  EXPECT_EQ(budgeted.statistics.find("with seven iterations"), static_cast<double>(budgeted.decision_time.decisions));
  EXPECT_EQ(budgeted.successes, unset.successes);  // dp-rerun has no use for a budget
}

}  // namespace
}  // namespace ontime
