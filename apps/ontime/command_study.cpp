// `ontime study compute-time|equal-time|anytime INSTANCE...`: the computation-time studies of
// the paper's Figs. 4-6. Each writes a CSV (atomically) and a PNG drawn from it, and prints
// where they are.

#include <fmt/format.h>

#include <filesystem>
#include <limits>

#include "cluster_job.hpp"
#include "common.hpp"
#include "memory_limits.hpp"
#include "number_options.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/report/report.hpp"
#include "ontime/run/experiments.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "output_paths.hpp"
#include "python_runner.hpp"

namespace ontime::cli {
namespace {

struct StudyOptions {
  std::vector<std::string> instances;
  std::string out = "out/studies";
  std::string multipliers = "0,0.5,1,1.5,2,2.5,3,3.5,4,4.5,5";
  bool no_plot = false;
  std::string act;         // empty: each instance's own "acting"
  StudySettings settings;  // the library's defaults: the paper's mcts against dp-rerun
  AllocatorFlags allocator;
};

std::vector<double> parse_multipliers(const std::string& text) {
  std::vector<double> values;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    try {
      std::size_t used = 0;
      values.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError("--log10-multipliers: '" + item + "' is not a number");
    }
    start = comma + 1;
  }
  return values;
}

// The CSV and PNG a study writes into --out: DIR/STEM.csv and DIR/STEM.png.
std::filesystem::path output_of(const StudyOptions& options, StudyKind kind, const char* extension) {
  const char* stem = kind == StudyKind::compute_time ? "compute_time"
                     : kind == StudyKind::equal_time ? "equal_time"
                                                     : "anytime";
  return std::filesystem::path(options.out) / (std::string(stem) + extension);
}

void run(const StudyOptions& given, StudyKind kind) {
  StudyOptions options = given;
  const std::vector<double> multipliers =
      kind == StudyKind::anytime ? parse_multipliers(options.multipliers) : std::vector<double>{};
  // Every instance loaded, the outputs (creating --out) and the memory checked first, so that a
  // bad file, path or cap stops the study before any computation.
  std::vector<StudyInstance> instances;
  for (const std::string& path : options.instances) {
    Problem problem = load_problem(path);
    if (!options.act.empty()) problem = problem.with_acting(*parse_acting(options.act));
    instances.push_back({std::move(problem), path, std::filesystem::path(path).stem().string()});
  }
  std::vector<OutputFile> outputs{{"--out", output_of(options, kind, ".csv")}};
  if (!options.no_plot) outputs.push_back({"--out", output_of(options, kind, ".png")});
  check_outputs(outputs, {options.instances.begin(), options.instances.end()}, MissingFolder::create);
  options.settings.parameters = options.allocator.values();
  options.settings.ranks = job_ranks();
  check_study_request(kind, instances, options.settings, flag_spelling());
  StudyRows rows;
  {
    ProgressBar bar("study " + std::string(to_string(kind)));
    options.settings.progress = [&bar](std::uint64_t done, std::uint64_t total) { bar.update(done, total); };
    rows = run_study(kind, instances, options.settings, multipliers);
  }
  if (!is_job_root()) return;  // rank 0 writes
  const std::string csv_path = output_of(options, kind, ".csv").string();
  write_file_atomically(csv_path, report::study_csv(rows, options.settings));
  fmt::print("wrote {}\n", csv_path);
  if (options.no_plot) return;
  const std::string png_path = output_of(options, kind, ".png").string();
  run_python_script("plot_study.py", png_path, [&](const std::string& drawing) {
    return std::vector<std::string>{std::string(to_string(kind)), csv_path, drawing};
  });
  fmt::print("wrote {}\n", png_path);
}

}  // namespace

void add_study_command(CLI::App& app) {
  CLI::App* study = app.add_subcommand("study", "Computation-time studies of mcts against dp-rerun (Figs. 4-6)");
  study->require_subcommand(1);
  const auto add = [study](const std::string& name, const std::string& description) {
    auto options = std::make_shared<StudyOptions>();
    CLI::App* command = study->add_subcommand(name, description);
    command->add_option("INSTANCE", options->instances, "Instance files (JSON, SPEC §5)")->required();
    command->add_option("--out", options->out, "Directory for the CSV and PNG")->capture_default_str();
    add_number_option(*command, "--episodes", options->settings.episodes, "Episodes per evaluated configuration",
                      std::uint64_t{1});
    add_number_option(*command, "--seed", options->settings.seed, "Seed of the hidden worlds");
    add_threads_option(*command, options->settings.threads, "Worker threads (0: one per hardware thread)");
    command->add_flag("--no-plot", options->no_plot, "Write the CSV only");
    add_act_option(*command, options->act,
                   "Concurrent: both allocators by their commit rules, every move a decision; the searcher's time "
                   "per decision is its time-budget");
    command
        ->add_option("--searcher", options->settings.searcher,
                     "The anytime allocator studied (" +
                         fmt::format("{}", fmt::join(allocator_registry().names({Capability::anytime}), ", ")) + ")")
        ->capture_default_str();
    command
        ->add_option("--reference", options->settings.reference,
                     "The stationary allocator it is measured against (its time per decision sets the searcher's)")
        ->capture_default_str();
    if (name == "anytime") {
      command
          ->add_option("--log10-multipliers", options->multipliers,
                       "Comma-separated exponents m: mcts gets 10^m times dp-rerun's time per decision")
          ->capture_default_str();
    }
    options->allocator.add_to(*command);
    command->callback([options, kind = study_kind(name)] { run(*options, kind); });
  };
  add("compute-time", "Fig. 4: total decision time per episode, mcts (--iterations) against dp-rerun");
  add("equal-time", "Fig. 5: mcts given exactly dp-rerun's measured time per decision");
  add("anytime", "Fig. 6: mcts success against log10 of a multiplier of dp-rerun's time");
}

}  // namespace ontime::cli
