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
  void add_to(CLI::App& command);
  AllocatorOptions options() const;
};

// Options shared by commands that run Monte Carlo episodes.
struct MonteCarloFlags {
  std::uint64_t episodes = 10'000;
  std::uint64_t seed = 1;
  unsigned threads = 0;
  void add_to(CLI::App& command);
  MonteCarloOptions options() const;
};

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
