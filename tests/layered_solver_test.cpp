#include "ontime/layered_solver.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "expectimax.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/value_bounds.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"
#include "support/thread_ranks.hpp"

namespace ontime {
namespace {

// Rounding slack of the bounds' inequalities (they are exact up to floating-point rounding).
constexpr double kRounding = 1e-12;

LayeredSolution solve(const Mdp& mdp, LayeredSolveOptions options = {}) {
  options.scratch_directory = ::testing::TempDir();
  return solve_layered(mdp, options);
}

void expect_same_as_memoised(const Mdp& mdp, const std::string& name, unsigned threads) {
  OptimalSolver memoised(mdp);
  const double optimum = memoised.solve(mdp.start());
  LayeredSolveOptions options;
  options.threads = threads;
  const LayeredSolution layered = solve(mdp, options);
  EXPECT_TRUE(layered.exact) << name;
  // The same sums in the same order: the same bits.
  EXPECT_EQ(layered.lower, optimum) << name;
  EXPECT_EQ(layered.upper, optimum) << name;
  EXPECT_EQ(layered.first_choice, memoised.best_choice(mdp.start()).value_or(-1)) << name;
  EXPECT_EQ(layered.states, memoised.states()) << name;
  std::uint64_t per_layer = 0;
  for (const LayerFigures& layer : layered.layers) per_layer += layer.states;
  EXPECT_EQ(per_layer, layered.states) << name;
}

TEST(LayeredSolver, AgreesWithTheMemoisedSolverOnThePaperInstances) {
  for (const char* name : {"figure1", "instance1", "instance2", "instance3", "instance4", "instance5"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    expect_same_as_memoised(mdp, name, 1);
    expect_same_as_memoised(mdp, name, 2);
  }
}

TEST(LayeredSolver, AgreesWithTheMemoisedSolverOnRandomInstances) {
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    const Problem problem = testing::random_instance(seed, 5, 4, 14);
    const Mdp mdp(problem);
    expect_same_as_memoised(mdp, "seed " + std::to_string(seed), seed % 2 == 0 ? 2 : 3);
  }
}

// Keys take as many words as the skeletons' fields need (a skeleton's fields never straddle
// two words): 6 skeletons of at most 2 actions with D = 12 need 6 x (2 + 4 + 4) bits, one word;
// 9 of them two; 16 with D = 60 (6-bit counters) four; 16 with D = 200 (8-bit) six, held in
// the widest key (16 words).
TEST(LayeredSolver, AgreesWithTheMemoisedSolverWithKeysOfSeveralWords) {
  struct Case {
    int skeletons;
    Steps deadline;
    std::size_t key_bytes;
  };
  for (const Case& wide : std::vector<Case>{{6, 12, 8}, {9, 12, 16}, {16, 60, 32}, {16, 200, 128}}) {
    const Problem problem = testing::wide_instance(7, wide.skeletons, 2, wide.deadline);
    const Mdp mdp(problem);
    LayeredSolveOptions options;
    options.max_states = 100'000;
    const LayeredSolution layered = solve(mdp, options);
    EXPECT_EQ(layered.key_bytes, wide.key_bytes) << wide.skeletons << " skeletons, D = " << wide.deadline;
    EXPECT_LE(layered.lower, layered.upper);
    if (layered.exact) expect_same_as_memoised(mdp, std::to_string(wide.skeletons) + " skeletons", 2);
  }
}

TEST(LayeredSolver, OneTwoAndThreeRanksGiveTheSameBits) {
  for (const char* name : {"instance1", "instance3"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    const LayeredSolution alone = solve(mdp);
    for (const int size : {2, 3}) {
      std::vector<LayeredSolution> solutions(static_cast<std::size_t>(size));
      testing::run_on_ranks(size, [&](const Ranks& ranks) {
        LayeredSolveOptions options;
        options.ranks = &ranks;
        options.threads = 1;
        options.policy_layers = 3;
        solutions[static_cast<std::size_t>(ranks.rank())] = solve(mdp, options);
      });
      for (const LayeredSolution& solution : solutions) {
        EXPECT_EQ(solution.lower, alone.lower) << name << " on " << size << " ranks";
        EXPECT_EQ(solution.first_choice, alone.first_choice);
        EXPECT_EQ(solution.states, alone.states);
        ASSERT_EQ(solution.layers.size(), alone.layers.size());
        for (std::size_t t = 0; t < alone.layers.size(); ++t)
          EXPECT_EQ(solution.layers[t].states, alone.layers[t].states);
        EXPECT_EQ(solution.policy.size(), solutions[0].policy.size());
      }
    }
  }
  // A cut over ranks gives one process's interval.
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  LayeredSolveOptions capped;
  capped.max_states = 300;
  const LayeredSolution alone = solve(mdp, capped);
  ASSERT_FALSE(alone.exact);
  testing::run_on_ranks(2, [&](const Ranks& ranks) {
    LayeredSolveOptions options = capped;
    options.ranks = &ranks;
    const LayeredSolution solution = solve(mdp, options);
    EXPECT_EQ(solution.lower, alone.lower);
    EXPECT_EQ(solution.upper, alone.upper);
    EXPECT_EQ(solution.frontier_layer, alone.frontier_layer);
  });
}

// Property: wherever a cap cuts the enumeration, lower <= V* <= upper, and a deeper cut gives a
// nested interval.
TEST(LayeredSolver, BoundsHoldTheOptimumWhereverTheyCut) {
  int cut = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const Problem problem = testing::random_instance(seed, 5, 4, 14);
    const Mdp mdp(problem);
    OptimalSolver memoised(mdp);
    const double optimum = memoised.solve(mdp.start());
    double lower = 0.0, upper = 1.0;
    for (const std::uint64_t cap : {1, 3, 10, 30, 100, 300, 1000}) {
      LayeredSolveOptions options;
      options.max_states = cap;
      const LayeredSolution solution = solve(mdp, options);
      EXPECT_LE(solution.lower, optimum + kRounding) << "seed " << seed << " cap " << cap;
      EXPECT_GE(solution.upper, optimum - kRounding) << "seed " << seed << " cap " << cap;
      EXPECT_GE(solution.lower, lower - kRounding) << "seed " << seed << " cap " << cap;
      EXPECT_LE(solution.upper, upper + kRounding) << "seed " << seed << " cap " << cap;
      lower = solution.lower;
      upper = solution.upper;
      if (!solution.exact) {
        ++cut;
        EXPECT_NE(solution.stopped_by.find("cap of " + std::to_string(cap) + " states"), std::string::npos);
        EXPECT_GE(solution.frontier_layer, 0);
      }
    }
  }
  EXPECT_GT(cut, 200);  // the caps did cut most instances, some several times
}

TEST(LayeredSolver, AStateCapOfOneGivesTheBoundsOfTheStart) {
  const Problem problem = testing::paper_instance("instance3");
  const Mdp mdp(problem);
  const ValueBounds bounds(mdp);
  LayeredSolveOptions options;
  options.max_states = 1;
  const LayeredSolution solution = solve(mdp, options);
  EXPECT_FALSE(solution.exact);
  EXPECT_EQ(solution.frontier_layer, 0);
  EXPECT_EQ(solution.lower, bounds.lower(mdp.start()));
  EXPECT_EQ(solution.upper, bounds.upper(mdp.start()));
  EXPECT_EQ(solution.first_choice, bounds.lower_choice(mdp.start()));
}

TEST(LayeredSolver, MemoryAndDiskCapsStopCleanlyWithTheLayerReached) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  LayeredSolveOptions memory;
  memory.max_memory_bytes = 4096;
  const LayeredSolution by_memory = solve(mdp, memory);
  EXPECT_FALSE(by_memory.exact);
  EXPECT_NE(by_memory.stopped_by.find("memory cap"), std::string::npos) << by_memory.stopped_by;
  EXPECT_NE(by_memory.stopped_by.find("layer " + std::to_string(by_memory.frontier_layer)), std::string::npos);
  LayeredSolveOptions disk;
  disk.max_disk_bytes = 200;
  const LayeredSolution by_disk = solve(mdp, disk);
  EXPECT_FALSE(by_disk.exact);
  EXPECT_NE(by_disk.stopped_by.find("disk cap"), std::string::npos) << by_disk.stopped_by;
  EXPECT_LE(by_disk.peak_disk_bytes, 200U);
  const double optimum = OptimalSolver(mdp).solve(mdp.start());
  for (const LayeredSolution* solution : {&by_memory, &by_disk}) {
    EXPECT_LE(solution->lower, optimum + kRounding);
    EXPECT_GE(solution->upper, optimum - kRounding);
  }
  int calls = 0;
  LayeredSolveOptions stopped;
  stopped.stop = [&calls] { return ++calls > 3; };
  const LayeredSolution by_stop = solve(mdp, stopped);
  EXPECT_FALSE(by_stop.exact);
  EXPECT_NE(by_stop.stopped_by.find("caller's request"), std::string::npos) << by_stop.stopped_by;
}

TEST(LayeredSolver, ThePolicyOfTheFirstLayersIsTheMemoisedSolversChoices) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  OptimalSolver memoised(mdp);
  memoised.solve(mdp.start());
  LayeredSolveOptions options;
  options.policy_layers = 4;
  const LayeredSolution solution = solve(mdp, options);
  std::uint64_t expected = 0;
  for (int t = 0; t < 4; ++t) expected += solution.layers[static_cast<std::size_t>(t)].states;
  ASSERT_EQ(solution.policy.size(), expected);
  int previous_time = 0;
  for (const PolicyEntry& entry : solution.policy) {
    EXPECT_GE(entry.state.time, previous_time);
    previous_time = entry.state.time;
    EXPECT_EQ(entry.choice, memoised.best_choice(entry.state).value_or(-1));
    EXPECT_EQ(entry.lower, memoised.solve(entry.state));
  }
  EXPECT_EQ(solution.policy.front().choice, solution.first_choice);
}

}  // namespace
}  // namespace ontime
