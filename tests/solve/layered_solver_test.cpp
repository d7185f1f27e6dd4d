#include "ontime/solve/layered_solver.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "ontime/allocators/optimal.hpp"
#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/error.hpp"
#include "solve/expectimax.hpp"
#include "solve/scratch_directory.hpp"
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
      options.split = SplitMode::never;  // the whole tree's frontier alone
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

// The successors are built from the state's key (the chosen group's fields and the groups
// whose time ran out rewritten), not by the Mdp: on instances with deeper trees and longer
// deadlines than above, the same values, first choices and state counts as the memoised solver.
TEST(LayeredSolver, AgreesWithTheMemoisedSolverOnDeeperTrees) {
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    const Problem problem = testing::random_instance(1000 + seed, 7, 5, 18);
    const Mdp mdp(problem);
    expect_same_as_memoised(mdp, "seed " + std::to_string(1000 + seed), 2);
  }
}

// Property: whatever the tolerance, the interval holds the optimum; 0 is exact, and dropping
// groups never enumerates more states.
TEST(LayeredSolver, ToleranceIntervalsHoldTheOptimum) {
  int widened = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const Problem problem = testing::random_instance(seed, 6, 4, 16);
    const Mdp mdp(problem);
    const double optimum = OptimalSolver(mdp).solve(mdp.start());
    const LayeredSolution exact = solve(mdp);
    for (const double tolerance : {0.0, 1e-3, 0.02, 0.1, 0.3}) {
      LayeredSolveOptions options;
      options.tolerance = tolerance;
      const LayeredSolution solution = solve(mdp, options);
      EXPECT_LE(solution.lower, optimum + kRounding) << "seed " << seed << " tolerance " << tolerance;
      EXPECT_GE(solution.upper, optimum - kRounding) << "seed " << seed << " tolerance " << tolerance;
      EXPECT_LE(solution.states, exact.states) << "seed " << seed << " tolerance " << tolerance;
      EXPECT_EQ(solution.exact, solution.dropped == 0) << "seed " << seed << " tolerance " << tolerance;
      if (tolerance == 0.0) {
        EXPECT_EQ(solution.lower, optimum) << "seed " << seed;
      }
      if (!solution.exact) ++widened;
    }
  }
  EXPECT_GT(widened, 50);  // the property was put to the test: groups were dropped
}

// Property: a split's interval holds the optimum, alone, with a tolerance and with a cap.
TEST(LayeredSolver, SplitIntervalsHoldTheOptimum) {
  int split = 0;
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    const Problem problem = testing::random_instance(seed, 6, 4, 16);
    const Mdp mdp(problem);
    if (split_plan(mdp).empty()) continue;
    ++split;
    const double optimum = OptimalSolver(mdp).solve(mdp.start());
    for (const double tolerance : {0.0, 0.05}) {
      for (const std::uint64_t cap : {0, 20}) {
        LayeredSolveOptions options;
        options.split = SplitMode::always;
        options.tolerance = tolerance;
        options.max_states = cap;
        const LayeredSolution solution = solve(mdp, options);
        const std::string where =
            "seed " + std::to_string(seed) + " tolerance " + std::to_string(tolerance) + " cap " + std::to_string(cap);
        EXPECT_LE(solution.lower, optimum + kRounding) << where;
        EXPECT_GE(solution.upper, optimum - kRounding) << where;
        EXPECT_EQ(solution.split_kept, split_plan(mdp)) << where;
        EXPECT_TRUE(solution.layers.empty()) << where;
        EXPECT_FALSE(solution.split_layers.empty()) << where;
      }
    }
  }
  EXPECT_GT(split, 100);
}

// The split keeps the subtree whose clairvoyant chance alone is the largest.
TEST(LayeredSolver, TheSplitKeepsTheStrongestFirstActionSubtree) {
  const Problem problem = testing::paper_instance("instance1");  // [0] and [1, 2, 3] begin differently
  const Mdp mdp(problem);
  const ValueBounds bounds(mdp);
  const State start = mdp.start();
  const bool second = bounds.group_upper(1, 0, 0, 0, 0) > bounds.group_upper(0, 0, 0, 0, 0);
  EXPECT_EQ(split_plan(mdp), second ? std::vector<int>({1, 2, 3}) : std::vector<int>({0}));
  const Problem shared = testing::paper_instance("instance5");  // all begin with a1_1
  EXPECT_TRUE(split_plan(Mdp(shared)).empty());
  LayeredSolveOptions options;
  options.split = SplitMode::always;
  const Mdp shared_mdp(shared);
  EXPECT_THROW(solve(shared_mdp, options), UsageError);
}

// When the bounded subtrees cannot succeed at all, the split is the exact solve of the rest.
TEST(LayeredSolver, ASplitWhoseOtherSubtreesCannotSucceedIsExact) {
  std::vector<Action> actions(3);
  actions[0] = {"a", Distribution::from_pmf({0.0, 0.3, 0.3, 0.2}), Distribution::from_pmf({0.5, 0.5})};
  actions[1] = {"b", Distribution::from_pmf({0.0, 0.4, 0.4}), Distribution::from_pmf({0.0, 1.0})};
  actions[2] = {"c", Distribution::from_pmf({0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0}), Distribution::from_pmf({1.0})};
  const Problem problem("weak-never", 5, 1.0, std::move(actions), {{0, 1}, {2}});
  const Mdp mdp(problem);
  LayeredSolveOptions options;
  options.split = SplitMode::always;
  const LayeredSolution solution = solve(mdp, options);
  EXPECT_TRUE(solution.exact);
  EXPECT_EQ(solution.split_weak_upper, 0.0);
  EXPECT_NEAR(solution.lower, OptimalSolver(mdp).solve(mdp.start()), kRounding);
  EXPECT_EQ(solution.upper, solution.lower);
}

// The fallback splits only when a cap cut the whole tree, and keeps the tighter end of each
// interval.
TEST(LayeredSolver, TheFallbackSplitsOnlyWhereACapCutTheWholeTree) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  LayeredSolveOptions options;
  options.split = SplitMode::fallback;
  const LayeredSolution uncut = solve(mdp, options);
  EXPECT_TRUE(uncut.exact);
  EXPECT_TRUE(uncut.split_kept.empty());
  options.max_states = 100;
  const LayeredSolution cut = solve(mdp, options);
  LayeredSolveOptions whole_only = options;
  whole_only.split = SplitMode::never;
  const LayeredSolution frontier = solve(mdp, whole_only);
  LayeredSolveOptions split_only = options;
  split_only.split = SplitMode::always;
  const LayeredSolution split = solve(mdp, split_only);
  ASSERT_FALSE(cut.split_kept.empty());
  EXPECT_EQ(cut.frontier_layer, frontier.frontier_layer);
  EXPECT_EQ(cut.lower, std::max(frontier.lower, split.lower));
  EXPECT_EQ(cut.upper, std::min(frontier.upper, split.upper));
  EXPECT_EQ(cut.states, frontier.states + split.split_states);
  EXPECT_LE(cut.lower, uncut.lower + kRounding);
  EXPECT_GE(cut.upper, uncut.lower - kRounding);
}

TEST(LayeredSolver, SplitsAndTolerancesGiveTheSameBitsOnOneTwoAndThreeRanks) {
  for (const char* name : {"instance1", "instance3"}) {
    const Problem problem = testing::paper_instance(name);
    const Mdp mdp(problem);
    for (const double tolerance : {0.0, 0.05}) {
      LayeredSolveOptions settings;
      settings.split = SplitMode::always;
      settings.tolerance = tolerance;
      const LayeredSolution alone = solve(mdp, settings);
      for (const int size : {2, 3}) {
        testing::run_on_ranks(size, [&](const Ranks& ranks) {
          LayeredSolveOptions options = settings;
          options.ranks = &ranks;
          options.threads = 2;
          const LayeredSolution solution = solve(mdp, options);
          EXPECT_EQ(solution.lower, alone.lower) << name << " on " << size << " ranks";
          EXPECT_EQ(solution.upper, alone.upper) << name << " on " << size << " ranks";
          EXPECT_EQ(solution.first_choice, alone.first_choice);
          EXPECT_EQ(solution.states, alone.states);
          EXPECT_EQ(solution.dropped, alone.dropped);
        });
      }
    }
  }
}

// A memory cap reached in the middle of a layer (a table that would grow past it) ends the
// forward pass there, with the interval of the layer before.
TEST(LayeredSolver, AMemoryCapInTheMiddleOfALayerEndsTheForwardPassCleanly) {
  // The navigation instance with a deadline of 16 steps: about 150,000 states, tens of MB.
  const Problem problem = testing::navigation_with_deadline(16);
  const Mdp mdp(problem);
  const LayeredSolution exact = solve(mdp);
  ASSERT_TRUE(exact.exact);
  ASSERT_GT(exact.peak_memory_bytes, 8U << 20);
  LayeredSolveOptions options;
  options.max_memory_bytes = exact.peak_memory_bytes / 3;
  options.split = SplitMode::never;
  const LayeredSolution cut = solve(mdp, options);
  EXPECT_FALSE(cut.exact);
  EXPECT_NE(cut.stopped_by.find("memory cap"), std::string::npos) << cut.stopped_by;
  EXPECT_LE(cut.peak_memory_bytes, options.max_memory_bytes);
  EXPECT_LE(cut.lower, exact.lower + kRounding);
  EXPECT_GE(cut.upper, exact.lower - kRounding);
}

}  // namespace
}  // namespace ontime

namespace ontime {
namespace {

std::string this_host() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return "localhost";
  std::string host(name);
  for (char& c : host) {
    if (c == '/') c = '_';
  }
  return host;
}

// The process id of a child that has ended and been reaped: a process that is gone.
long gone_process() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

// Of the scratch directories in a folder, only those of this host's gone processes are removed:
// never a live process's (this one's, init's), never another host's, never a name of another form.
TEST(ScratchDirectory, RemovesOnlyTheScratchOfThisHostsGoneProcesses) {
  const std::filesystem::path folder = std::filesystem::path(::testing::TempDir()) / "stale-scratch";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  const std::string host = this_host();
  const long gone = gone_process();
  const std::string dead = "ontime-layers-" + host + "-" + std::to_string(gone) + "-rank1-aB3dE9";
  const std::vector<std::string> kept = {
      "ontime-layers-" + host + "-" + std::to_string(::getpid()) + "-rank0-Qw12Er",  // alive: this process
      "ontime-layers-" + host + "-1-rank0-Zx98Cv",                                   // alive: init
      "ontime-layers-another-host-" + std::to_string(gone) + "-rank0-Ty56Ui",        // not seen from here
      "ontime-layers-" + std::to_string(gone) + "-rank0-Op09As",                     // no host: another form
      "my-ontime-layers-" + host + "-" + std::to_string(gone) + "-rank0-Df45Gh",
  };
  std::filesystem::create_directory(folder / dead);
  { std::ofstream(folder / dead / "layer-3.codes") << std::string(1000, 'x'); }
  { std::ofstream(folder / dead / "layer-4.keys") << std::string(24, 'y'); }
  for (const std::string& name : kept) std::filesystem::create_directory(folder / name);

  std::vector<std::pair<std::filesystem::path, std::uint64_t>> noticed;
  const int removed = remove_stale_scratch(folder, [&noticed](const std::filesystem::path& path, std::uint64_t bytes) {
    noticed.emplace_back(path, bytes);
  });
  EXPECT_EQ(removed, 1);
  ASSERT_EQ(noticed.size(), 1U);
  EXPECT_EQ(noticed[0].first, folder / dead);
  EXPECT_EQ(noticed[0].second, 1024U);
  EXPECT_FALSE(std::filesystem::exists(folder / dead));
  for (const std::string& name : kept) EXPECT_TRUE(std::filesystem::is_directory(folder / name)) << name;

  // A solve over the folder does the same before it starts, and leaves nothing of its own.
  std::filesystem::create_directory(folder / dead);
  LayeredSolveOptions options;
  options.scratch_directory = folder;
  int reported = 0;
  options.on_stale_scratch = [&reported](const std::filesystem::path&, std::uint64_t) { ++reported; };
  const Problem problem = testing::paper_instance("instance1");
  EXPECT_NEAR(solve_layered(Mdp(problem), options).lower, 0.942, 1e-12);
  EXPECT_EQ(reported, 1);
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(folder)) ++entries;
  EXPECT_EQ(entries, kept.size());
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace ontime
