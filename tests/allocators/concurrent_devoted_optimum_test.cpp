// The devoted optimum acting while planning (SPEC §10 with §9's chains and expiry): the optimum of
// the instance with that skeleton alone, never below the devoted eager policy and above it where
// waiting for a chain pays; dp and dp-rerun follow it, so that on the cup they earn the optimum.
#include "ontime/solve/concurrent_devoted_optimum.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/solve/concurrent_contiguous_success.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

// `problem` with skeleton k alone and the skeletons whose path is a prefix of k's (an episode ends
// through them): k's actions, their rewards and the chains.
Problem alone(const Problem& problem, int k) {
  const std::span<const int> path = problem.skeleton(k);
  std::vector<Action> actions;
  for (const int action : path) actions.push_back(problem.action(action));
  std::vector<std::vector<int>> skeletons;
  std::vector<SkeletonReward> rewards;
  for (int j = 0; j < problem.skeleton_count(); ++j) {
    const std::span<const int> other = problem.skeleton(j);
    if (other.size() > path.size() || !std::equal(other.begin(), other.end(), path.begin())) continue;
    std::vector<int> indices(other.size());
    for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<int>(i);
    skeletons.push_back(std::move(indices));
    if (problem.has_rewards()) rewards.push_back(problem.rewards()[static_cast<std::size_t>(j)]);
  }
  return Problem(problem.name(), problem.deadline(), problem.step_seconds(), std::move(actions), std::move(skeletons),
                 "", std::move(rewards), std::vector<ExogenousChain>(problem.chains().begin(), problem.chains().end()))
      .with_acting(Acting::concurrent);
}

double optimum(const Problem& problem) {
  const ConcurrentMdp mdp(problem);
  ConcurrentSolver solver(mdp);
  return solver.solve(mdp.start());
}

double exact_value(const ConcurrentMdp& mdp, const std::string& kind) {
  const auto allocator = make_concurrent_allocator_factory(kind, mdp)();
  return evaluate_exactly(mdp, *allocator).expected_reward;
}

TEST(ConcurrentDevotedOptimum, IsTheOptimumOfTheSkeletonAloneAndAtLeastTheEagerPolicys) {
  // Random instances with chains and expiry, half with rewards, every third with backtracking.
  const int count = testing::repetitions_to_check(150);
  int skeletons = 0;
  int waiting_pays = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    Problem problem = testing::with_random_chains(testing::random_instance(seed + 9100, 3, 3, 10), seed, seed % 2 == 0);
    if (seed % 3 == 0) problem = testing::with_backtracking(problem, seed + 40);
    problem = problem.with_acting(Acting::concurrent);
    const ConcurrentMdp mdp(problem);
    ConcurrentDevotedOptimum devoted(mdp);
    ConcurrentContiguousSuccess eager(mdp, Aggregation::self);
    const ConcurrentState start = mdp.start();
    for (int k = 0; k < mdp.skeleton_count(); ++k) {
      if (!ConcurrentMdp::is_live(start, k)) {
        EXPECT_EQ(devoted.value(start, k), 0.0);
        continue;
      }
      ++skeletons;
      const double value = devoted.value(start, k);
      EXPECT_NEAR(value, optimum(alone(problem, k)), 1e-12) << "seed " << seed << " skeleton " << k;
      const double eager_value = eager.value(start, k);
      EXPECT_GE(value, eager_value - 1e-12) << "seed " << seed << " skeleton " << k;
      if (value > eager_value + 1e-9) ++waiting_pays;
      // Its move is one the full state allows.
      const ConcurrentMdp::Move move = devoted.move(start, k);
      if (move.is_start()) {
        const std::vector<int> startable = mdp.startable(start);
        EXPECT_NE(std::find(startable.begin(), startable.end(), move.start), startable.end()) << seed;
      } else if (move.refine != ConcurrentMdp::kWait) {
        // A step along k: on k, or on a skeleton whose path is a prefix of k's (naming the group).
        const std::span<const int> along = problem.members(problem.skeleton(move.refine).back());
        EXPECT_TRUE(std::binary_search(along.begin(), along.end(), k)) << seed << " " << move.refine << " " << k;
      }
    }
  }
  EXPECT_GT(skeletons, count);
  EXPECT_GT(waiting_pays, count / 20);  // the instances do have doors worth waiting for
}

TEST(ConcurrentDevotedOptimum, DpAndDpRerunWaitForTheCupsDoor) {
  // The cup through the door: the optimum (0.880233) is what the first skeleton alone reaches by
  // waiting for the door; the eager policy devoted to it earns far less (0.660796).
  const Problem cup = load_problem(testing::source_path("data/instances/chains/cup-through-the-door.json"))
                          .with_acting(Acting::concurrent);
  const ConcurrentMdp mdp(cup);
  ConcurrentContiguousSuccess eager(mdp, Aggregation::self);
  const double best = optimum(cup);
  EXPECT_NEAR(best, optimum(alone(cup, 0)), 1e-12);
  EXPECT_LT(eager.value(mdp.start(), 0), best - 0.2);
  for (const std::string kind : {"dp", "dp-rerun"}) EXPECT_NEAR(exact_value(mdp, kind), best, 1e-12) << kind;
  // Without chains nothing changes: the devoted optimum is the eager value (instance 1).
  const ConcurrentMdp paper(testing::paper_instance("instance1").with_acting(Acting::concurrent));
  ConcurrentDevotedOptimum devoted(paper);
  ConcurrentContiguousSuccess paper_eager(paper, Aggregation::self);
  for (int k = 0; k < paper.skeleton_count(); ++k) {
    EXPECT_NEAR(devoted.value(paper.start(), k), paper_eager.value(paper.start(), k), 1e-12) << k;
  }
}

}  // namespace
}  // namespace ontime
