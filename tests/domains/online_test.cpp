#include <gtest/gtest.h>

#include <set>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/domains/manipulation.hpp"
#include "ontime/domains/navigation.hpp"
#include "ontime/domains/planner_world.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/episode_runner.hpp"
#include "support/paper.hpp"

namespace ontime::domains {
namespace {

struct OnlineFixture {
  NavigationDomain domain{load_navigation_world(testing::source_path("data/domains/navigation.json"))};
  Problem problem{load_problem(testing::source_path("data/instances/navigation.json"))};
  Mdp mdp{problem};
  PlannerWorldOptions options{EffortSettings{EffortUnit::collision_checks, 1200.0}, false, std::nullopt};
};

const OnlineFixture& online_fixture() {
  static const OnlineFixture instance;
  return instance;
}

// One episode in a fresh planner world, with the world's counters of that episode.
struct PlannerEpisode {
  EpisodeResult result;
  double started = 0, found = 0;
};

PlannerEpisode run_planner_episode(const OnlineFixture& f, Allocator& allocator, std::uint64_t seed) {
  PlannerWorld world(f.domain, f.problem, f.options);
  PlannerEpisode episode{run_episode(f.mdp, allocator, world, seed)};
  Statistics statistics;
  world.collect_statistics(statistics);
  episode.started = statistics.find("refinements_started").value_or(-1);
  episode.found = statistics.find("refinements_found").value_or(-1);
  return episode;
}

TEST(Online, AnAllocatorInterleavesRealRefinementsStepByStep) {
  const OnlineFixture& f = online_fixture();
  // Round-robin gives each skeleton a step in turn: several refinements are under way at once,
  // each resumed where it stopped.
  const auto allocator = make_allocator_factory("round-robin", f.mdp)();
  int interleaved = 0;
  for (std::uint64_t seed = 0; seed < 5; ++seed) {
    const PlannerEpisode episode = run_planner_episode(f, *allocator, seed);
    EXPECT_NE(episode.result.status, Status::running);
    EXPECT_LE(episode.result.steps_used, f.problem.deadline());
    EXPECT_GE(episode.started, episode.found);
    EXPECT_LE(episode.started, f.problem.action_count());
    interleaved += episode.started >= 3 ? 1 : 0;  // one first action per skeleton group
  }
  EXPECT_EQ(interleaved, 5);
}

TEST(Online, ASuccessRefinedEveryActionOfTheSolution) {
  const OnlineFixture& f = online_fixture();
  const auto allocator = make_allocator_factory("dp", f.mdp)();
  int successes = 0;
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    const PlannerEpisode episode = run_planner_episode(f, *allocator, seed);
    if (episode.result.status != Status::success) continue;
    ++successes;
    ASSERT_GE(episode.result.solution, 0);
    EXPECT_GE(episode.found, f.problem.skeleton_length(episode.result.solution));
    EXPECT_LE(episode.result.steps_used, f.problem.deadline());
  }
  EXPECT_GT(successes, 0);
}

TEST(Online, SameSeedSameEpisodesWhateverTheThreads) {
  const OnlineFixture& f = online_fixture();
  const AllocatorFactory factory = make_allocator_factory("dp-rerun", f.mdp);
  const WorldFactory worlds = planner_worlds(f.domain, f.problem, f.options);
  MonteCarloOptions options;
  options.episodes = 12;
  options.seed = 3;
  options.threads = 1;
  const MonteCarloResult one = run_episodes(f.mdp, worlds, factory, options);
  options.threads = 2;
  const MonteCarloResult two = run_episodes(f.mdp, worlds, factory, options);
  EXPECT_EQ(one.successes, two.successes);
  EXPECT_DOUBLE_EQ(one.world_statistics.find("refinements_started").value_or(-1),
                   two.world_statistics.find("refinements_started").value_or(-2));
  EXPECT_GE(one.world_statistics.find("refinements_started").value_or(0), 12.0);
  EXPECT_EQ(one.episodes, 12u);
}

// Records the seed of every episode it begins (a randomised allocator draws its stream from it).
class SeedRecorder final : public Allocator {
 public:
  SeedRecorder(std::unique_ptr<Allocator> inner, std::vector<std::uint64_t>& seeds)
      : inner_(std::move(inner)), seeds_(&seeds) {}
  std::string_view name() const noexcept override { return inner_->name(); }
  void begin_episode(std::uint64_t seed) override {
    seeds_->push_back(seed);
    inner_->begin_episode(seed);
  }
  int choose(const State& state) override { return inner_->choose(state); }
  bool is_stationary() const noexcept override { return false; }

 private:
  std::unique_ptr<Allocator> inner_;
  std::vector<std::uint64_t>* seeds_;
};

// Against the real planner, as against hidden worlds, every episode's allocator draws from its
// own stream (they once all began from seed 0, so mcts repeated one stream in every episode).
TEST(Online, EveryEpisodeGetsItsOwnRandomStream) {
  const OnlineFixture& f = online_fixture();
  const AllocatorFactory inner = make_allocator_factory("mcts", f.mdp);
  std::vector<std::uint64_t> seeds;
  const AllocatorFactory recording = [&] { return std::make_unique<SeedRecorder>(inner(), seeds); };
  MonteCarloOptions options;
  options.episodes = 3;
  options.seed = 3;
  options.threads = 1;
  run_episodes(f.mdp, planner_worlds(f.domain, f.problem, f.options), recording, options);
  ASSERT_EQ(seeds.size(), 3U);
  EXPECT_EQ(std::set<std::uint64_t>(seeds.begin(), seeds.end()).size(), 3U) << "two episodes share one random stream";
  for (std::uint64_t e = 0; e < 3; ++e) EXPECT_EQ(seeds[e], stream_seed(stream_seed(3, e), 1));
}

// A refinement that gives up (the kitchen whose cubby takes one pair of grasps): the step reports
// the backtrack to the action before, that action and every one below it lose their motions, and
// the next step on it starts a new attempt; episodes stay the same whatever the threads.
TEST(Online, ARefinementThatGivesUpSendsTheEpisodeBackToTheActionBefore) {
  const ManipulationDomain domain(load_manipulation_world(testing::source_path("data/domains/kitchen-grasps.json")));
  const Problem problem = load_problem(testing::source_path("data/instances/kitchen-grasps.json"));
  const Mdp mdp(problem);
  const PlannerWorldOptions options{
      EffortSettings{EffortUnit::collision_checks, domain.world().collection.checks_per_second}, false, std::nullopt};
  PlannerWorld world(domain, problem, options);
  world.begin_episode(5);
  const int pick = problem.find_action("move+pick(B1)");
  const int place = problem.find_action("move+place(B1,S)");
  ASSERT_GE(pick, 0);
  ASSERT_GE(place, 0);
  Observation seen;
  Steps spent = 0;
  for (; spent < problem.deadline() && !seen.refined; ++spent) seen = world.step(pick, spent);
  ASSERT_TRUE(seen.refined);
  seen = Observation::not_yet();
  for (spent = 0; spent < problem.deadline() && !seen.refined && !seen.is_backtrack(); ++spent)
    seen = world.step(place, spent);
  ASSERT_TRUE(seen.is_backtrack()) << "the direct placement is infeasible with the grasp the pick took";
  EXPECT_EQ(seen.culprit, pick);
  EXPECT_EQ(world.refinement(pick), nullptr);
  EXPECT_EQ(world.refinement(place), nullptr);
  EXPECT_FALSE(world.step(pick, 0).is_backtrack());
  EXPECT_NE(world.refinement(pick), nullptr);
  Statistics statistics;
  world.collect_statistics(statistics);
  EXPECT_EQ(statistics.find("backtracks").value_or(-1), 1.0);
  EXPECT_EQ(statistics.find("refinements_started").value_or(-1), 3.0);

  const AllocatorFactory factory = make_allocator_factory("dp-rerun", mdp);
  MonteCarloOptions episodes;
  episodes.episodes = 6;
  episodes.seed = 2;
  episodes.threads = 1;
  const MonteCarloResult one = run_episodes(mdp, planner_worlds(domain, problem, options), factory, episodes);
  episodes.threads = 2;
  const MonteCarloResult two = run_episodes(mdp, planner_worlds(domain, problem, options), factory, episodes);
  EXPECT_EQ(one.successes, two.successes);
  EXPECT_GT(one.world_statistics.find("backtracks").value_or(0), 0.0);
  EXPECT_DOUBLE_EQ(one.world_statistics.find("backtracks").value_or(-1),
                   two.world_statistics.find("backtracks").value_or(-2));
  EXPECT_DOUBLE_EQ(one.world_statistics.find("refinements_started").value_or(-1),
                   two.world_statistics.find("refinements_started").value_or(-2));
}

}  // namespace
}  // namespace ontime::domains
