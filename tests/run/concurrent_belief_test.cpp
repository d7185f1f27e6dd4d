// Acting while planning with a belief (SPEC §10 "Beliefs"): a world's model that keeps hopeless
// skeletons has the same values as the canonical one; an allocator deciding with the world's own
// distributions through seen_by_belief makes the same moves, so its episodes and exact value are
// the same; a misleading belief is played in the world, never above the world's optimum, and a hand
// case gives the value the belief earns.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/util/random.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

// The random instances of these tests: plain, with backtracking (SPEC §7), with chains and expiry
// (SPEC §9, rewards in half of them), acting while planning.
Problem random_acting_instance(std::uint64_t seed) {
  Problem problem = testing::random_instance(seed + 700, 4, 3, 10);
  if (seed % 3 == 1) problem = testing::with_backtracking(problem, seed);
  if (seed % 3 == 2) problem = testing::with_random_chains(problem, seed, seed % 2 == 0);
  return problem.with_acting(Acting::concurrent);
}

// A belief of the same skeletons that misleads: execution distributions (and, without backtracking,
// planning distributions) shuffled among the actions; one seed in four also believes every other
// action never found.
Problem misleading_belief(const Problem& truth, std::uint64_t seed) {
  std::vector<Action> actions(truth.actions().begin(), truth.actions().end());
  SplitMix64 generator(seed);
  for (std::size_t i = actions.size(); i > 1; --i) {
    if (!truth.has_backtracking()) std::swap(actions[i - 1].planning, actions[generator() % i].planning);
    std::swap(actions[i - 1].execution, actions[generator() % i].execution);
  }
  for (std::size_t i = 0; seed % 4 == 3 && i < actions.size(); i += 2) {
    actions[i].planning = Distribution::from_pmf({0.0});
    actions[i].backtrack = Distribution::from_pmf({0.0});
    actions[i].culprits.clear();
  }
  return with_distributions_of(truth, truth.with_actions(std::move(actions)));
}

// The stationary kinds that take the mode and need nothing but the instance.
std::vector<std::string> stationary_kinds() {
  std::vector<std::string> kinds;
  for (const std::string& name : allocator_registry().acting_names()) {
    if (allocator_registry().find(name).capabilities.has(Capability::stationary) && name != "ppo") {
      kinds.push_back(name);
    }
  }
  return kinds;
}

double exact_reward(const ConcurrentMdp& world, const ConcurrentAllocatorFactory& factory) {
  const auto allocator = factory();
  return evaluate_exactly(world, *allocator).expected_reward;
}

TEST(ConcurrentMdpKeepingHopeless, TheOptimumIsTheCanonicalModels) {
  int kept_more = 0;
  const int count = testing::repetitions_to_check(300);
  for (int i = 0; i < count; ++i) {
    const Problem problem = random_acting_instance(static_cast<std::uint64_t>(i));
    const ConcurrentMdp canonical(problem);
    const ConcurrentMdp keeping(problem, HopelessSkeletons::kept);
    EXPECT_EQ(keeping.keeps_hopeless(), true);
    EXPECT_EQ(canonical.keeps_hopeless(), problem.has_backtracking());
    ConcurrentSolver canonical_solver(canonical);
    ConcurrentSolver keeping_solver(keeping);
    EXPECT_NEAR(keeping_solver.solve(keeping.start()), canonical_solver.solve(canonical.start()), 1e-12) << i;
    // The kept states drop nothing more than E does; the model's own view of them is canonical.
    EXPECT_EQ(canonical.canonical(keeping.start()), canonical.start()) << i;
    if (keeping.start() != canonical.start()) ++kept_more;
  }
  // Some starts keep a skeleton the canonical model drops (a test that could not tell them apart
  // would prove nothing).
  EXPECT_GT(kept_more, count / 20);
}

TEST(SeenByBelief, TheWorldsOwnDistributionsMakeTheSameMovesAndNumbers) {
  const int count = testing::repetitions_to_check(150);
  for (int i = 0; i < count; ++i) {
    const Problem problem = random_acting_instance(static_cast<std::uint64_t>(i));
    const ConcurrentMdp canonical(problem);
    const ConcurrentMdp keeping(problem, HopelessSkeletons::kept);
    const ConcurrentMdp believed(with_distributions_of(problem, problem));
    for (const std::string& kind : allocator_registry().acting_names()) {
      if (kind == "ppo") continue;
      const ParameterValues values =
          kind == "mcts" || kind == "branch-and-bound" ? ParameterValues{{"iterations", "30"}} : ParameterValues{};
      const ConcurrentAllocatorFactory own = make_concurrent_allocator_factory(kind, canonical, values);
      const ConcurrentAllocatorFactory believing =
          seen_by_belief(believed, make_concurrent_allocator_factory(kind, believed, values));
      MonteCarloOptions options;
      options.episodes = 40;
      options.seed = static_cast<std::uint64_t>(i);
      options.threads = 1;
      const MonteCarloResult by_own = run_monte_carlo(canonical, own, options);
      const MonteCarloResult by_belief = run_monte_carlo(keeping, believing, options);
      EXPECT_EQ(by_belief.successes, by_own.successes) << kind << " " << i;
      EXPECT_EQ(by_belief.mean_reward, by_own.mean_reward) << kind << " " << i;
      if (allocator_registry().find(kind).capabilities.has(Capability::stationary)) {
        EXPECT_EQ(exact_reward(keeping, believing), exact_reward(canonical, own)) << kind << " " << i;
      }
    }
  }
}

TEST(SeenByBelief, AMisleadingBeliefIsPlayedInTheWorld) {
  int below = 0;
  int checked = 0;
  const int count = testing::repetitions_to_check(300);
  for (int i = 0; i < count; ++i) {
    const auto seed = static_cast<std::uint64_t>(i);
    const Problem problem = random_acting_instance(seed);
    const ConcurrentMdp keeping(problem, HopelessSkeletons::kept);
    const ConcurrentMdp canonical(problem);
    const ConcurrentMdp believed(misleading_belief(problem, seed));
    ConcurrentSolver solver(canonical);
    const double optimum = solver.solve(canonical.start());
    for (const std::string& kind : stationary_kinds()) {
      const ConcurrentAllocatorFactory believing =
          seen_by_belief(believed, make_concurrent_allocator_factory(kind, believed));
      const double value = exact_reward(keeping, believing);
      EXPECT_LE(value, optimum + 1e-12) << kind << " " << i;
      EXPECT_GE(value, 0.0) << kind << " " << i;
      below += value < exact_reward(canonical, make_concurrent_allocator_factory(kind, canonical)) - 1e-12 ? 1 : 0;
      ++checked;
      if (kind != "dp-rerun" || i % 10 != 0) continue;
      // Its episodes in the world agree with its exact value (within 4 standard errors).
      MonteCarloOptions options;
      options.episodes = 4000;
      options.seed = seed;
      const MonteCarloResult episodes = run_monte_carlo(keeping, believing, options);
      EXPECT_NEAR(episodes.mean_reward, value, 4 * episodes.reward_ci95 / 1.96 + 1e-12) << i;
    }
  }
  // The beliefs do mislead: a share of the allocators earn less than with the world's own model.
  EXPECT_GT(below, checked / 20);
}

// Two skeletons of one action each, deadline 3: a0 is found at step 1 and runs 1 step; a1 is never
// found. The belief swaps their planning, so it counts skeleton 0 hopeless and refines a1 to the
// end: the world's 1 becomes 0. A belief that counts both hopeless idles: 0 as well.
TEST(SeenByBelief, AHandCaseEarnsWhatTheBeliefChooses) {
  const Distribution found_at_1 = Distribution::from_pmf({0.0, 1.0});
  const Distribution never = Distribution::from_pmf({0.0});
  const Distribution one_step = Distribution::from_pmf({0.0, 1.0});
  const Problem world = Problem("hand", 3, 1.0, {{"a0", found_at_1, one_step}, {"a1", never, one_step}}, {{0}, {1}})
                            .with_acting(Acting::concurrent);
  const ConcurrentMdp keeping(world, HopelessSkeletons::kept);
  const ConcurrentMdp canonical(world);
  EXPECT_EQ(exact_reward(canonical, make_concurrent_allocator_factory("dp-rerun", canonical)), 1.0);
  // The world's own model kept: skeleton 1 is live there, though hopeless.
  EXPECT_TRUE(ConcurrentMdp::is_live(keeping.start(), 1));
  EXPECT_FALSE(ConcurrentMdp::is_live(canonical.start(), 1));

  const Problem swapped("belief", 3, 1.0, {{"a0", never, one_step}, {"a1", found_at_1, one_step}}, {{0}, {1}});
  const ConcurrentMdp believed(with_distributions_of(world, swapped));
  for (const char* kind : {"dp-rerun", "optimal", "greedy", "round-robin"}) {
    EXPECT_EQ(exact_reward(keeping, seen_by_belief(believed, make_concurrent_allocator_factory(kind, believed))), 0.0)
        << kind;
  }
  const Problem hopeless("belief", 3, 1.0, {{"a0", never, one_step}, {"a1", never, one_step}}, {{0}, {1}});
  const ConcurrentMdp believed_hopeless(with_distributions_of(world, hopeless));
  const auto idle =
      seen_by_belief(believed_hopeless, make_concurrent_allocator_factory("dp-rerun", believed_hopeless))();
  EXPECT_EQ(idle->choose(keeping.start()), ConcurrentMdp::Move{});
  EXPECT_EQ(evaluate_exactly(keeping, *idle).expected_reward, 0.0);
}

}  // namespace
}  // namespace ontime
