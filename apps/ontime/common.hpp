#pragma once
// Shared pieces of the `ontime` commands: registration, option groups, output helpers.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ontime/allocators.hpp"
#include "ontime/evaluation.hpp"

namespace ontime::cli {

using Json = nlohmann::ordered_json;

// Each command registers itself as a subcommand; its callback does the work and throws on error.
void add_solve_command(CLI::App& app);
void add_evaluate_command(CLI::App& app);
void add_table_command(CLI::App& app);
void add_study_command(CLI::App& app);
void add_train_command(CLI::App& app);
void add_reduce_knapsack_command(CLI::App& app);
void add_fit_command(CLI::App& app);
void add_sample_log_command(CLI::App& app);
void add_plot_command(CLI::App& app);
void add_collect_command(CLI::App& app);
void add_map_command(CLI::App& app);
void add_run_command(CLI::App& app);

// Options shared by commands that build allocators.
struct AllocatorFlags {
  std::string aggregation = "sum";
  std::size_t max_states = OptimalSolver::kDefaultMaxStates;
  double exploration = 0.5;
  std::uint64_t iterations = 0;  // 0: 10,000 without --time-budget, unlimited with it
  double time_budget = 0;        // seconds per decision, 0: none
  std::string rollout = "random";
  std::size_t max_tree_mib = 1024;
  std::vector<std::string> policies;  // ppo: one policy file, or one per instance
  void add_to(CLI::App& command);
  // Options for the instance at `index` of `instance_count` (selects its ppo policy, if any).
  AllocatorOptions options(std::size_t index = 0, std::size_t instance_count = 1) const;
};

// Options shared by commands that run Monte Carlo episodes.
struct MonteCarloFlags {
  std::uint64_t episodes = 10'000;
  std::uint64_t seed = 1;
  unsigned threads = 0;
  void add_to(CLI::App& command);
  MonteCarloOptions options() const;
};

// Adds the required `--solver NAME` option, its help listing the allocators.
CLI::Option* add_solver_option(CLI::App& command, std::string& solver);

// Checks that every name is a known allocator; throws UsageError otherwise.
void check_solver_names(const std::vector<std::string>& names);

// Prints JSON to stdout, two-space indented.
void print_json(const Json& value);

// A progress bar on stderr, shown only when stderr is a terminal.
class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  ~ProgressBar();
  void update(std::uint64_t done, std::uint64_t total);

 private:
  std::string label_;
  bool enabled_;
  int last_percent_ = -1;
};

}  // namespace ontime::cli
