#include <gtest/gtest.h>

#include "ontime/allocator_registry.hpp"
#include "ontime/domains/navigation.hpp"
#include "ontime/domains/online.hpp"
#include "ontime/instance_io.hpp"
#include "support/paper.hpp"

namespace ontime::domains {
namespace {

struct Fixture {
  NavigationDomain domain{load_navigation_world(testing::source_path("data/domains/navigation.json"))};
  Problem problem{load_problem(testing::source_path("data/instances/navigation.json"))};
  Mdp mdp{problem};
  OnlineOptions options{EffortSettings{EffortUnit::collision_checks, 1200.0}, false};
};

const Fixture& fixture() {
  static const Fixture instance;
  return instance;
}

TEST(Online, AnAllocatorInterleavesRealRefinementsStepByStep) {
  const Fixture& f = fixture();
  // Round-robin gives each skeleton a step in turn: several refinements are under way at once,
  // each resumed where it stopped.
  const auto allocator = make_allocator_factory("round-robin", f.mdp)();
  int interleaved = 0;
  for (std::uint64_t seed = 0; seed < 5; ++seed) {
    const OnlineEpisode episode = run_online_episode(f.domain, f.mdp, *allocator, seed, f.options);
    EXPECT_NE(episode.status, Status::running);
    EXPECT_LE(episode.steps_used, f.problem.deadline());
    EXPECT_GE(episode.actions_started, episode.actions_refined);
    EXPECT_LE(episode.actions_started, f.problem.action_count());
    interleaved += episode.actions_started >= 3 ? 1 : 0;  // one first action per skeleton group
  }
  EXPECT_EQ(interleaved, 5);
}

TEST(Online, ASuccessRefinedEveryActionOfTheSolution) {
  const Fixture& f = fixture();
  const auto allocator = make_allocator_factory("dp", f.mdp)();
  int successes = 0;
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    const OnlineEpisode episode = run_online_episode(f.domain, f.mdp, *allocator, seed, f.options);
    if (episode.status != Status::success) continue;
    ++successes;
    ASSERT_GE(episode.solution, 0);
    EXPECT_GE(episode.actions_refined, f.problem.skeleton_length(episode.solution));
    EXPECT_LE(episode.steps_used, f.problem.deadline());
  }
  EXPECT_GT(successes, 0);
}

TEST(Online, SameSeedSameEpisodesWhateverTheThreads) {
  const Fixture& f = fixture();
  const AllocatorFactory factory = make_allocator_factory("dp-rerun", f.mdp);
  const OnlineSummary one = run_online(f.domain, f.mdp, factory, 12, 3, 1, f.options);
  const OnlineSummary two = run_online(f.domain, f.mdp, factory, 12, 3, 2, f.options);
  EXPECT_EQ(one.successes, two.successes);
  EXPECT_DOUBLE_EQ(one.mean_actions_started, two.mean_actions_started);
  EXPECT_EQ(one.episodes, 12u);
}

}  // namespace
}  // namespace ontime::domains
