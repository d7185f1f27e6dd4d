// `ontime table INSTANCE...`: the layout of the paper's Table I (run/table.hpp) — one row per
// instance, one column per allocator (sampled mean ± 95%, exact value with --exact), the exact
// optimum, and the mean decision time of each allocator — printed by the report module as a
// Markdown table or JSON.

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

#include "common.hpp"
#include "memory_limits.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/report/report.hpp"
#include "ontime/run/table.hpp"
#include "ontime/util/error.hpp"

namespace ontime::cli {
namespace {

// The time left of a table from the cost of each column's episodes: the episodes run row by row,
// column by column (episodes per cell), and an episode of one solver may cost 50,000 of
// another's (mcts against dp), so the share done alone misleads by orders of magnitude. Each
// column's seconds per episode is measured on its own episodes; until every column with
// episodes left has run some, there is no estimate.
class TableTimeLeft {
 public:
  TableTimeLeft(std::uint64_t episodes, std::size_t columns)
      : episodes_(episodes), seconds_(columns, 0.0), counted_(columns, 0), last_(std::chrono::steady_clock::now()) {}

  std::optional<double> seconds_left(std::uint64_t done, std::uint64_t total) {
    const auto now = std::chrono::steady_clock::now();
    if (episodes_ == 0 || seconds_.empty()) return std::nullopt;
    if (done > done_) {
      // The time since the last report is the column's whose cell holds the last episode done.
      const std::size_t column = column_of(done - 1);
      seconds_[column] += std::chrono::duration<double>(now - last_).count();
      counted_[column] += done - done_;
      done_ = done;
    }
    last_ = now;
    double left = 0;
    for (std::uint64_t at = done; at < total;) {
      const std::uint64_t cell_end = (at / episodes_ + 1) * episodes_;
      const std::uint64_t here = std::min(cell_end, total) - at;
      const std::size_t column = column_of(at);
      if (counted_[column] == 0) return std::nullopt;
      left += seconds_[column] / static_cast<double>(counted_[column]) * static_cast<double>(here);
      at += here;
    }
    return left;
  }

 private:
  std::size_t column_of(std::uint64_t episode) const {
    return static_cast<std::size_t>((episode / episodes_) % seconds_.size());
  }

  std::uint64_t episodes_;
  std::vector<double> seconds_;         // by column: time spent on its episodes
  std::vector<std::uint64_t> counted_;  // by column: its episodes done
  std::uint64_t done_ = 0;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace

void add_table_command(CLI::App& app) {
  struct Options {
    std::vector<std::string> instances;
    std::vector<std::string> solvers = default_table_solvers();
    bool exact = false;
    bool json = false;
    std::vector<std::string> acts;  // empty: each instance's own mode
    AllocatorFlags allocator;
    MonteCarloFlags monte_carlo;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("table", "Table I: success of several allocators on several instances");
  command->add_option("INSTANCE", options->instances, "Instance files (JSON, SPEC §5)")->required();
  // Split here rather than by CLI11, which drops empty names ("dp,,greedy") that must be refused.
  command
      ->add_option_function<std::string>(
          "--solvers",
          [options](const std::string& text) {
            options->solvers.clear();
            if (text.empty()) return;
            // (A loop rather than std::views::split, which clang 14 cannot parse in libstdc++ 12.)
            std::string_view rest(text);
            for (std::size_t comma = rest.find(','); comma != std::string_view::npos; comma = rest.find(',')) {
              options->solvers.emplace_back(rest.substr(0, comma));
              rest.remove_prefix(comma + 1);
            }
            options->solvers.emplace_back(rest);
          },
          "Comma-separated allocators, one column each")
      ->default_str(fmt::format("{}", fmt::join(options->solvers, ",")));
  command->add_flag("--exact", options->exact, "Add exact success probabilities and the exact optimum");
  command
      ->add_option("--act", options->acts,
                   "plan-first, concurrent, or both comma-separated (one row per instance and mode, labelled "
                   "'NAME (concurrent)' when acting while planning; SPEC §10); default: each instance's own "
                   "\"acting\". Rows acting while planning take the allocators with a commit rule ('ontime "
                   "allocators'); the default columns are then those")
      ->delimiter(',')
      ->check(CLI::IsMember({"plan-first", "concurrent"}));
  command->add_flag("--json", options->json, "Print JSON");
  options->monte_carlo.add_to(*command);
  options->allocator.add_to(*command);
  command->callback([options, command] {
    TableOptions table;
    table.solvers = options->solvers;
    if (table.solvers.empty()) throw UsageError("--solvers: give at least one allocator");
    // Not given: the library's defaults, which leave out the kinds without a commit rule when a
    // row acts while planning.
    if (command->get_option("--solvers")->count() == 0) table.solvers.clear();
    table.exact = options->exact;
    const MonteCarloOptions monte_carlo = options->monte_carlo.options();
    table.episodes = monte_carlo.episodes;
    table.seed = monte_carlo.seed;
    table.threads = monte_carlo.threads;
    table.ranks = monte_carlo.ranks;
    apply_tool_layered_settings(table.layered);
    // Every instance loaded and every request checked first: a bad file or value stops the
    // command before any long computation.
    std::vector<TableInstance> instances;
    for (std::size_t i = 0; i < options->instances.size(); ++i) {
      const std::string& path = options->instances[i];
      const Problem problem = load_problem(path);
      const std::string stem = std::filesystem::path(path).stem().string();
      const ParameterValues values = options->allocator.values(i, options->instances.size());
      if (options->acts.empty()) {
        instances.push_back(
            {problem, path, stem + (problem.acting() == Acting::concurrent ? " (concurrent)" : ""), values});
        continue;
      }
      for (const std::string& act : options->acts) {
        const Acting acting = *parse_acting(act);
        instances.push_back(
            {problem.with_acting(acting), path, stem + (acting == Acting::concurrent ? " (concurrent)" : ""), values});
      }
    }
    check_table_request(instances, table, flag_spelling());
    if (table.solvers.empty())
      table.solvers =
          default_table_solvers(std::any_of(instances.begin(), instances.end(), [](const TableInstance& instance) {
            return instance.problem.acting() == Acting::concurrent;
          }));
    ProgressBar bar("table");
    TableTimeLeft time_left(table.episodes, table.solvers.size());
    table.progress = [&bar, &time_left](std::uint64_t done, std::uint64_t total) {
      bar.update(done, total, time_left.seconds_left(done, total));
    };
    const Table measured = measure_table(instances, table);
    table.progress = nullptr;
    if (options->json) {
      fmt::print("{}\n", report::to_json(measured));
    } else {
      fmt::print("{}", report::to_markdown(measured, flag_spelling()));
    }
  });
}

}  // namespace ontime::cli
