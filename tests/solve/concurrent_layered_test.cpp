// Acting while planning (SPEC §10): the layered solver (`solve --act concurrent --method layered`)
// against the memoised solver, to the bit, on random instances with and without backtracking
// (SPEC §7), rewards (§8), chains and expiry (§9), on the paper's instances and on data/instances;
// the same bits whatever the thread count; and, cut short by a cap or the stop condition, a
// certified interval around the optimum.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/solve/concurrent_layered_solver.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

LayeredSolveOptions layered_options(unsigned threads = 2) {
  LayeredSolveOptions options;
  options.threads = threads;
  return options;
}

Problem instance_file(const std::string& path) {
  return load_problem(testing::source_path("data/instances/" + path + ".json"));
}

// The layered solver's value and first move are the memoised solver's to the bit, and it
// enumerates exactly the states the memoised solver keeps (one per key of its memo). Returns the
// number of states.
std::uint64_t check_layered_is_memoised(const Problem& problem, const std::string& label,
                                        HopelessSkeletons hopeless = HopelessSkeletons::dropped) {
  const ConcurrentMdp mdp(problem, hopeless);
  ConcurrentSolver solver(mdp);
  const double optimum = solver.solve(mdp.start());
  const ConcurrentSolution solution = solve_concurrent_layered(mdp, layered_options());
  EXPECT_TRUE(solution.exact) << label;
  EXPECT_EQ(solution.lower, optimum) << label;
  EXPECT_EQ(solution.upper, optimum) << label;
  EXPECT_EQ(solution.first, solver.best_move(mdp.start()).value_or(ConcurrentMdp::Move{})) << label;
  EXPECT_EQ(solution.solved, solver.states()) << label;
  EXPECT_EQ(solution.frontier_layer, -1) << label;
  std::uint64_t per_level = 0;
  for (const LayerFigures& level : solution.layers) {
    per_level += level.states;
    EXPECT_TRUE(level.backward) << label;
  }
  EXPECT_EQ(per_level, solution.solved) << label;
  return solution.solved;
}

TEST(ConcurrentLayeredSolver, TheValueAndTheFirstMoveAreTheMemoisedSolversToTheBit) {
  const int count = testing::repetitions_to_check(150);
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const Problem problem = testing::random_instance(seed + 9100, 4, 4, 12);
    const Problem chosen = seed % 3 == 0 ? testing::with_random_rewards(problem, seed) : problem;
    check_layered_is_memoised(chosen, "seed " + std::to_string(seed));
    // Keys that are the states themselves.
    check_layered_is_memoised(chosen, "kept, seed " + std::to_string(seed), HopelessSkeletons::kept);
  }
  for (const char* name : {"figure1", "instance1", "instance2", "instance3", "instance4", "instance5"}) {
    check_layered_is_memoised(testing::paper_instance(name), name);
  }
  // Several blocks per level, so that both threads value states.
  EXPECT_GT(check_layered_is_memoised(testing::navigation_with_deadline(14), "navigation at 14 steps"), 100'000U);
}

TEST(ConcurrentLayeredSolver, WithChainsAndExpiryTheValueIsTheMemoisedSolversToTheBit) {
  const int count = testing::repetitions_to_check(120);
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    check_layered_is_memoised(
        testing::with_random_chains(testing::random_instance(seed + 9300, 4, 3, 10), seed, seed % 2 == 0),
        "chains, seed " + std::to_string(seed));
  }
  for (const char* name : {"chains/meeting-through-the-queue", "chains/cup-through-the-door"}) {
    check_layered_is_memoised(instance_file(name), name);
  }
}

TEST(ConcurrentLayeredSolver, WithBacktrackingTheValueIsTheMemoisedSolversToTheBit) {
  const int count = testing::repetitions_to_check(120);
  int backtracking = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    Problem problem = testing::with_backtracking(testing::random_instance(seed + 9500, 4, 4, 11), seed);
    if (seed % 3 == 0) problem = testing::with_random_rewards(problem, seed);
    if (seed % 4 == 0) problem = testing::with_random_chains(problem, seed, false);
    backtracking += problem.has_backtracking() ? 1 : 0;
    check_layered_is_memoised(problem, "backtracking, seed " + std::to_string(seed));
  }
  EXPECT_GT(backtracking, count * 3 / 4);
  for (const char* name : {"kitchen-grasps", "backtracking/grasp-and-place"}) {
    check_layered_is_memoised(instance_file(name), name);
  }
}

TEST(ConcurrentLayeredSolver, TheBitsDoNotDependOnTheThreadCount) {
  const Problem problem = testing::navigation_with_deadline(13);
  const ConcurrentMdp mdp(problem);
  const ConcurrentSolution one = solve_concurrent_layered(mdp, layered_options(1));
  for (const unsigned threads : {2U, 3U}) {
    const ConcurrentSolution many = solve_concurrent_layered(mdp, layered_options(threads));
    EXPECT_EQ(many.lower, one.lower) << threads;
    EXPECT_EQ(many.first, one.first) << threads;
    ASSERT_EQ(many.layers.size(), one.layers.size()) << threads;
    for (std::size_t n = 0; n < one.layers.size(); ++n) EXPECT_EQ(many.layers[n].states, one.layers[n].states);
  }
  // Cut short, the interval too.
  LayeredSolveOptions capped = layered_options(1);
  capped.max_states = one.solved / 3;
  const ConcurrentSolution cut_one = solve_concurrent_layered(mdp, capped);
  capped.threads = 3;
  const ConcurrentSolution cut_many = solve_concurrent_layered(mdp, capped);
  EXPECT_EQ(cut_one.lower, cut_many.lower);
  EXPECT_EQ(cut_one.upper, cut_many.upper);
  EXPECT_EQ(cut_one.frontier_layer, cut_many.frontier_layer);
}

// Cut by the state cap, the memory cap or the stop condition at every level it can reach, the
// solver gives an interval around the optimum whose ends meet it no better than the exact solve.
void check_layered_cut_short(const Problem& problem) {
  const ConcurrentMdp mdp(problem);
  const ConcurrentSolution exact = solve_concurrent_layered(mdp, layered_options());
  ASSERT_TRUE(exact.exact) << problem.name();
  const double optimum = exact.lower;
  constexpr double kRounding = 1e-12;
  const auto check = [&](const ConcurrentSolution& solution, const std::string& stopped_by, const std::string& label) {
    ASSERT_FALSE(solution.exact) << label;
    EXPECT_EQ(solution.stopped_by, stopped_by) << label;
    EXPECT_GE(solution.frontier_layer, 0) << label;
    EXPECT_EQ(solution.layers.size(), static_cast<std::size_t>(solution.frontier_layer) + 1) << label;
    EXPECT_LE(solution.lower, optimum + kRounding) << label;
    EXPECT_GE(solution.upper, optimum - kRounding) << label;
    EXPECT_LE(solution.lower, solution.upper) << label;
  };
  double widest = 0, narrowest = 1;
  // (The start's level is always expanded: a cut comes at level 1 at the earliest.)
  for (std::size_t level = 1; level + 1 < exact.layers.size(); level += 2) {
    std::uint64_t through = 0;
    for (std::size_t n = 0; n <= level; ++n) through += exact.layers[n].states;
    LayeredSolveOptions capped = layered_options();
    capped.max_states = through;  // level `level` fits, the next does not
    const ConcurrentSolution solution = solve_concurrent_layered(mdp, capped);
    check(solution, "the state cap", problem.name() + ", cap " + std::to_string(through));
    EXPECT_EQ(solution.frontier_layer, static_cast<int>(level)) << problem.name();
    widest = std::max(widest, solution.upper - solution.lower);
    narrowest = std::min(narrowest, solution.upper - solution.lower);
  }
  // Deeper frontiers give narrower intervals here: the bounds are tight near the deadline.
  EXPECT_LT(narrowest, widest) << problem.name();
  LayeredSolveOptions memory = layered_options();
  memory.max_memory_bytes = exact.peak_memory_bytes / 2;
  check(solve_concurrent_layered(mdp, memory), "the memory cap", problem.name() + ", memory");
  LayeredSolveOptions stopped = layered_options();
  int calls = 0;
  stopped.stop = [&calls] { return ++calls > 3; };
  check(solve_concurrent_layered(mdp, stopped), "the stop condition", problem.name() + ", stop");
}

TEST(ConcurrentLayeredSolver, CutShortItsIntervalHoldsTheOptimum) {
  check_layered_cut_short(testing::navigation_with_deadline(13));
  // With backtracking (SPEC §7): the kitchen whose placements may blame their grasps.
  check_layered_cut_short(instance_file("kitchen-grasps"));
  // With chains (SPEC §9): the frontier's lower ends are the best start that ends the episode.
  check_layered_cut_short(instance_file("chains/meeting-through-the-queue"));
}

// The levels go to the scratch folder and leave it empty at the end; the disk cap cuts the pass
// with an interval; what the plan-first layered solver takes and this one does not is refused.
TEST(ConcurrentLayeredSolver, ItsScratchIsRemovedAndItsDiskCapped) {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("ontime-concurrent-levels-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  const ConcurrentMdp mdp(testing::navigation_with_deadline(12));
  LayeredSolveOptions options = layered_options();
  options.scratch_directory = folder;
  const ConcurrentSolution exact = solve_concurrent_layered(mdp, options);
  ASSERT_TRUE(exact.exact);
  EXPECT_GT(exact.peak_disk_bytes, 100'000U);
  EXPECT_TRUE(std::filesystem::is_empty(folder));
  options.max_disk_bytes = exact.peak_disk_bytes / 2;
  const ConcurrentSolution cut = solve_concurrent_layered(mdp, options);
  EXPECT_FALSE(cut.exact);
  EXPECT_EQ(cut.stopped_by, "the disk cap");
  EXPECT_LE(cut.peak_disk_bytes, options.max_disk_bytes);
  EXPECT_LE(cut.lower, exact.lower + 1e-12);
  EXPECT_GE(cut.upper, exact.lower - 1e-12);
  EXPECT_TRUE(std::filesystem::is_empty(folder));
  std::filesystem::remove_all(folder);

  LayeredSolveOptions tolerance = layered_options();
  tolerance.tolerance = 0.1;
  EXPECT_THROW(solve_concurrent_layered(mdp, tolerance), UsageError);
  LayeredSolveOptions split = layered_options();
  split.split = SplitMode::always;
  EXPECT_THROW(solve_concurrent_layered(mdp, split), UsageError);
  LayeredSolveOptions policy = layered_options();
  policy.policy_layers = 1;
  EXPECT_THROW(solve_concurrent_layered(mdp, policy), UsageError);
}

}  // namespace
}  // namespace ontime
