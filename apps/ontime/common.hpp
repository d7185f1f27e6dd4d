#pragma once
// Shared pieces of the `ontime` commands: registration, option groups, output helpers.

#include <CLI/CLI.hpp>
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/run/evaluation.hpp"

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
void add_fit_chain_command(CLI::App& app);
void add_sample_log_command(CLI::App& app);
void add_plot_command(CLI::App& app);
void add_collect_command(CLI::App& app);
void add_map_command(CLI::App& app);
void add_predict_command(CLI::App& app);
void add_score_command(CLI::App& app);
void add_adapt_command(CLI::App& app);
void add_fit_strength_command(CLI::App& app);
void add_generate_world_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_tamp_command(CLI::App& app);
void add_allocators_command(CLI::App& app);

// The allocator kinds and their parameters as Markdown tables (`ontime allocators`).
std::string allocators_markdown();

// The whole command line, every command registered (main and the tests use it).
std::unique_ptr<CLI::App> make_app();

// One option `--NAME` per parameter declared in the allocator registry (its help, type and
// default from the declaration), for the commands that build allocators. A parameter given
// once applies to every instance of the command; given once per instance, to each in order.
struct AllocatorFlags {
  std::map<std::string, std::vector<std::string>> given;  // by parameter name
  void add_to(CLI::App& command);
  // The values for the instance at `index` of `instance_count`, each checked against its
  // declaration; UsageError naming the option otherwise.
  ParameterValues values(std::size_t index = 0, std::size_t instance_count = 1) const;
  // The state cap of exact computations (the `max-states` parameter).
  std::size_t max_states() const;
};

// Options shared by commands that run Monte Carlo episodes.
// Refuses (UsageError, exit 2) what `solver` may hold on `problem` (its declared memory need: a
// search tree's cap for each thread of the run, the exact solver's table) when that exceeds the
// memory available; the message names the flag.
void check_allocator_memory(const std::string& solver, const Problem& problem, const ParameterValues& values,
                            std::uint64_t episodes, unsigned threads);

struct MonteCarloFlags {
  std::uint64_t episodes = 10'000;
  std::uint64_t seed = 1;
  unsigned threads = 0;
  void add_to(CLI::App& command);
  MonteCarloOptions options() const;
  // check_allocator_memory for this run's episodes and threads.
  void check_allocator_memory(const std::string& solver, const Problem& problem, const ParameterValues& values) const;
};

// Adds the required `--solver NAME` option, its help listing the allocators.
CLI::Option* add_solver_option(CLI::App& command, std::string& solver);

// Adds `--act plan-first|concurrent` (SPEC §10); `act` stays empty when it is not given, so that the
// instance's own "acting" applies. `what` ends the help: how the command takes the mode.
CLI::Option* add_act_option(CLI::App& command, std::string& act, const std::string& what);

// Checks that every name is a known allocator (the CLI calls them solvers), none empty and
// none twice; throws UsageError otherwise.
void check_solver_names(const std::vector<std::string>& names);

// Prints JSON to stdout, two-space indented.
void print_json(const Json& value);

// Progress on stderr, on the rank that prints. On a terminal, a bar redrawn in place; otherwise
// (a log, CI, a pipe) a plain line now and then, at most every progress_line_seconds():
//   ontime table: 12/35 (34%), 1m12s elapsed, about 2m20s left
// Nothing at all with --quiet, and no line for work that ends before the first interval.
class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  // The time left estimated from the share done (items of one cost).
  void update(std::uint64_t done, std::uint64_t total);
  // The time left as the caller estimates it; none printed without one (nullopt: too early to
  // tell, e.g. items of a kind whose cost nothing has measured yet).
  void update(std::uint64_t done, std::uint64_t total, std::optional<double> seconds_left);
  // For work whose total is not known in advance: the label and `text` on one line, redrawn.
  void status(std::string_view text);

 private:
  enum class Mode { off, bar, lines };
  // In lines mode: whether a line is due (and, when it is, the clock moves on to the next one).
  bool line_due();
  std::string label_;
  Mode mode_;
  int last_percent_ = -1;
  std::chrono::steady_clock::time_point started_;
  std::chrono::steady_clock::time_point next_line_;
};

// --quiet (every command): no progress bar and no progress lines.
void set_quiet(bool quiet) noexcept;
// Seconds between two progress lines when stderr is not a terminal: 5, or the environment's
// ONTIME_PROGRESS_SECONDS (a number >= 0; 0 prints every change, for tests).
double progress_line_seconds();
// "1h02m", "3m07s", "42s": a duration as a progress line shows it.
std::string progress_duration(double seconds);

}  // namespace ontime::cli
