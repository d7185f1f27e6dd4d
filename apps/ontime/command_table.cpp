// `ontime table INSTANCE...`: the layout of the paper's Table I — one row per instance, one
// column per allocator (sampled mean ± 95%, exact value with --exact), the exact optimum, and
// the mean decision time of each allocator. An exact part that would need more than
// --max-states states is reported as such in its cell (the sampled value stands), so that one
// large instance does not cost the whole table; the states and seconds of every exact part are
// listed below the table.

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <string_view>

#include "common.hpp"
#include "markdown_table.hpp"
#include "memory_limits.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/solve/layered_solver.hpp"
#include "ontime/util/error.hpp"

namespace ontime::cli {
namespace {

// An exact computation: its value, or the cap it reached; its states and seconds.
struct ExactPart {
  std::optional<double> value;
  bool cap_reached = false;
  std::size_t states = 0;  // memoised states; at the cap: the cap
  // The optimum at the cap: the layered solver's certified interval.
  std::optional<double> lower, upper;
  double seconds = 0;
};

struct Cell {
  MonteCarloResult sampled;
  std::optional<ExactPart> exact;  // with --exact, for stationary allocators
};

struct Row {
  std::string path;
  std::string label;
  std::string name;
  std::vector<Cell> cells;
  std::optional<ExactPart> optimum;
};

// Runs an exact computation that returns (value, states); a ResourceLimitError becomes a
// reached cap of `max_states`.
template <class Compute>
ExactPart exact_part(std::size_t max_states, const Compute& compute) {
  ExactPart part;
  const auto started = std::chrono::steady_clock::now();
  try {
    const auto [value, states] = compute();
    part.value = value;
    part.states = states;
  } catch (const ResourceLimitError&) {
    part.cap_reached = true;
    part.states = max_states;
  }
  part.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return part;
}

std::string exact_text(const ExactPart& part) {
  if (part.value) return fmt::format("{:.4f}", *part.value);
  if (part.lower) return fmt::format("[{:.4f}, {:.4f}]", *part.lower, *part.upper);
  return "cap reached";
}

Json exact_json(const ExactPart& part) {
  Json out;
  if (part.value) out["value"] = *part.value;
  if (part.lower) {
    out["lower_bound"] = *part.lower;
    out["upper_bound"] = *part.upper;
  }
  out["cap_reached"] = part.cap_reached;
  out["states"] = part.states;
  out["seconds"] = part.seconds;
  return out;
}

struct TableOptions {
  std::vector<std::string> instances;
  std::vector<std::string> solvers;
  bool exact = false;
  bool json = false;
  AllocatorFlags allocator;
  MonteCarloFlags monte_carlo;
};

// One row: every column's Monte Carlo run and, with --exact, exact parts. `factories` are the
// columns' allocators for this row's instance.
Row measure_row(const TableOptions& options, std::size_t index, const Mdp& mdp,
                const std::vector<AllocatorFactory>& factories, std::size_t max_states,
                const std::function<void(std::uint64_t)>& progress) {
  Row row;
  row.path = options.instances[index];
  row.label = std::filesystem::path(row.path).stem().string();
  row.name = mdp.problem().name();
  std::uint64_t finished = 0;
  for (std::size_t column = 0; column < options.solvers.size(); ++column) {
    const std::string& solver = options.solvers[column];
    const AllocatorFactory& factory = factories[column];
    MonteCarloOptions monte_carlo = options.monte_carlo.options();
    monte_carlo.progress = [&](std::uint64_t done, std::uint64_t) { progress(finished + done); };
    Cell cell{run_monte_carlo(mdp, factory, monte_carlo), std::nullopt};
    finished += monte_carlo.episodes;
    if (options.exact && allocator_registry().find(solver).capabilities.has(Capability::stationary)) {
      const auto allocator = factory();
      cell.exact = exact_part(max_states, [&] {
        const ExactEvaluation evaluation = evaluate_exactly(mdp, *allocator, max_states);
        return std::pair{evaluation.success_probability, evaluation.states};
      });
    }
    row.cells.push_back(std::move(cell));
  }
  if (options.exact) {
    // The layered solver: past the state cap it gives a certified interval rather than nothing
    // (the whole tree's frontier, and a split of it where its first actions differ).
    const auto started = std::chrono::steady_clock::now();
    LayeredSolveOptions layered;
    layered.max_states = max_states;
    layered.split = SplitMode::fallback;
    layered.ranks = options.monte_carlo.options().ranks;
    layered.threads = options.monte_carlo.threads;
    apply_tool_layered_settings(layered);
    const LayeredSolution solution = solve_layered(mdp, layered);
    ExactPart optimum;
    optimum.states = solution.states;
    optimum.cap_reached = !solution.exact;
    if (solution.exact) {
      optimum.value = solution.lower;
    } else {
      // Every policy's exact success probability is at most the optimum, so the row's exact
      // cells are lower bounds as certain as the layered solver's own.
      optimum.lower = solution.lower;
      for (const Cell& cell : row.cells) {
        if (cell.exact && cell.exact->value) optimum.lower = std::max(*optimum.lower, *cell.exact->value);
      }
      optimum.upper = solution.upper;
    }
    optimum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    row.optimum = optimum;
  }
  return row;
}

Json table_json(const TableOptions& options, const std::vector<Row>& rows) {
  Json out;
  out["episodes"] = options.monte_carlo.episodes;
  out["seed"] = options.monte_carlo.seed;
  out["solvers"] = options.solvers;
  out["rows"] = Json::array();
  for (const Row& row : rows) {
    Json line;
    line["instance"] = row.path;
    line["name"] = row.name;
    Json cells = Json::object();
    for (std::size_t s = 0; s < options.solvers.size(); ++s) {
      const Cell& cell = row.cells[s];
      Json entry;
      entry["success_rate"] = cell.sampled.success_rate;
      entry["ci95"] = cell.sampled.ci95;
      entry["decision_time_us"] = {{"median", cell.sampled.decision_time.median_us},
                                   {"p99", cell.sampled.decision_time.p99_us},
                                   {"mean", cell.sampled.decision_time.mean_us}};
      if (cell.exact) {
        if (cell.exact->value) entry["exact_success_probability"] = *cell.exact->value;
        entry["exact"] = exact_json(*cell.exact);
      }
      cells[options.solvers[s]] = entry;
    }
    line["solvers"] = cells;
    if (row.optimum) {
      if (row.optimum->value) line["optimal_success_probability"] = *row.optimum->value;
      line["optimal_states"] = row.optimum->states;
      line["optimum"] = exact_json(*row.optimum);
    }
    out["rows"].push_back(line);
  }
  return out;
}

void print_table(const TableOptions& options, const std::vector<Row>& rows) {
  std::vector<std::string> header{"instance"};
  for (const std::string& solver : options.solvers) header.push_back(solver);
  if (options.exact) header.emplace_back("optimum");
  std::vector<std::vector<std::string>> body;
  std::vector<double> latency_sum(options.solvers.size(), 0.0);
  for (const Row& row : rows) {
    std::vector<std::string> line{row.label};
    for (std::size_t s = 0; s < row.cells.size(); ++s) {
      const Cell& cell = row.cells[s];
      std::string text = fmt::format("{:.3f} ± {:.3f}", cell.sampled.success_rate, cell.sampled.ci95);
      if (cell.exact) text += " (" + exact_text(*cell.exact) + ")";
      line.push_back(text);
      latency_sum[s] += cell.sampled.decision_time.mean_us;
    }
    if (options.exact) line.push_back(exact_text(*row.optimum));
    body.push_back(std::move(line));
  }
  std::vector<std::string> latency{"mean decision time (µs)"};
  for (const double sum : latency_sum) latency.push_back(fmt::format("{:.3f}", sum / static_cast<double>(rows.size())));
  if (options.exact) latency.emplace_back("");
  body.push_back(std::move(latency));

  fmt::print(
      "Success probability: mean ± 95% over {} episodes (seed {}){}.\n\n", options.monte_carlo.episodes,
      options.monte_carlo.seed,
      options.exact
          ? "; exact value in parentheses; optimum = exact expectimax, or a certified [lower, upper] past --max-states"
          : "");
  fmt::print("{}", render_markdown(header, body));
  if (!options.exact) return;
  fmt::print("\nExact parts (states, seconds; 'cap reached': more than --max-states {} states):\n",
             options.allocator.max_states());
  for (const Row& row : rows) {
    std::vector<std::string> parts;
    for (std::size_t s = 0; s < row.cells.size(); ++s) {
      const auto& exact = row.cells[s].exact;
      if (!exact) continue;
      parts.push_back(fmt::format("{} {}{} states, {:.1f} s", options.solvers[s], exact->cap_reached ? "over " : "",
                                  exact->states, exact->seconds));
    }
    parts.push_back(fmt::format("optimum {}{} states{}, {:.1f} s", row.optimum->cap_reached ? "over " : "",
                                row.optimum->states, row.optimum->cap_reached ? " (certified interval)" : "",
                                row.optimum->seconds));
    fmt::print("- {}: {}.\n", row.label, fmt::join(parts, "; "));
  }
}

// Refuses an instance given twice (the same file under any name): its row would repeat.
void check_distinct_instances(const std::vector<std::string>& paths) {
  for (std::size_t i = 0; i < paths.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      std::error_code error;
      if (paths[i] == paths[j] || std::filesystem::equivalent(paths[i], paths[j], error)) {
        throw UsageError(fmt::format("{}: instance given twice (as argument {} and {}); one row per instance", paths[i],
                                     j + 1, i + 1));
      }
    }
  }
}

}  // namespace

void add_table_command(CLI::App& app) {
  auto options = std::make_shared<TableOptions>();
  // The default columns: every allocator that needs nothing beyond the instance, the optimum
  // (its own column with --exact) aside.
  options->solvers = allocator_registry().names({}, {Capability::needs_policy, Capability::optimal});
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
  command->add_flag("--json", options->json, "Print JSON");
  options->monte_carlo.add_to(*command);
  options->allocator.add_to(*command);
  command->callback([options] {
    check_solver_names(options->solvers);
    check_distinct_instances(options->instances);
    // Load every instance and make every column's allocators first (policies loaded, parameters
    // checked): a bad file or value stops the command before any long computation.
    std::vector<Problem> problems;
    for (const std::string& path : options->instances) problems.push_back(load_problem(path));
    std::vector<std::unique_ptr<Mdp>> mdps;
    std::vector<std::vector<AllocatorFactory>> factories(problems.size());
    std::vector<std::size_t> max_states;
    for (std::size_t i = 0; i < problems.size(); ++i) {
      const ParameterValues parameters = options->allocator.values(i, problems.size());
      mdps.push_back(std::make_unique<Mdp>(problems[i]));
      max_states.push_back(max_states_of(parameters));
      const bool exact_work =
          options->exact ||
          std::any_of(options->solvers.begin(), options->solvers.end(), [](const std::string& solver) {
            return allocator_registry().find(solver).capabilities.has(Capability::optimal);
          });
      if (exact_work) check_state_cap_memory(problems[i], max_states.back(), options->instances[i]);
      for (const std::string& solver : options->solvers) {
        options->monte_carlo.check_tree_memory(solver, parameters);
        factories[i].push_back(make_allocator_factory(solver, *mdps[i], parameters));
      }
    }

    ProgressBar bar("table");
    const std::uint64_t per_row = options->monte_carlo.episodes * options->solvers.size();
    const std::uint64_t total = per_row * problems.size();
    std::vector<Row> rows;
    for (std::size_t i = 0; i < problems.size(); ++i) {
      rows.push_back(
          measure_row(*options, i, *mdps[i], factories[i], max_states[i],
                      [&bar, i, per_row, total](std::uint64_t done) { bar.update(i * per_row + done, total); }));
    }
    if (options->json) {
      print_json(table_json(*options, rows));
    } else {
      print_table(*options, rows);
    }
  });
}

}  // namespace ontime::cli
