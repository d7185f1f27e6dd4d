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
  std::uint64_t episodes = 1'000;
  std::uint64_t seed = 1;
  unsigned threads = 0;
  std::string searcher = "mcts";
  std::string reference = "dp-rerun";
  AllocatorFlags allocator;
};

std::string label_of(const std::string& path) { return std::filesystem::path(path).stem().string(); }

// The searcher's iterations per search (its declared counters), 0 for a kind that does not search.
double iterations_per_search(const std::string& searcher, const MonteCarloResult& result) {
  return ontime::iterations_per_search(allocator_registry().find(searcher), result.statistics).value_or(0.0);
}

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
std::filesystem::path output_of(const StudyOptions& options, const std::string& kind, const char* extension) {
  const std::string stem = kind == "compute-time" ? "compute_time" : kind == "equal-time" ? "equal_time" : "anytime";
  return std::filesystem::path(options.out) / (stem + extension);
}

// Loads every instance and checks the outputs (creating --out) first, so that a bad file or
// path stops the study before any computation.
std::vector<Problem> prepare(const StudyOptions& options, const std::string& kind) {
  std::vector<Problem> problems;
  for (const std::string& path : options.instances) problems.push_back(load_problem(path));
  std::vector<OutputFile> outputs{{"--out", output_of(options, kind, ".csv")}};
  if (!options.no_plot) outputs.push_back({"--out", output_of(options, kind, ".png")});
  check_outputs(outputs, {options.instances.begin(), options.instances.end()}, MissingFolder::create);
  // Memory the study would need (the searcher's trees; the anytime study's exact optimum).
  const ParameterValues parameters = options.allocator.values();
  for (std::size_t i = 0; i < problems.size(); ++i) {
    check_allocator_memory(options.searcher, problems[i], parameters, options.episodes, options.threads);
    if (kind == "anytime")
      check_exact_work(problems[i], max_states_of(parameters), options.instances[i], flag_spelling());
  }
  return problems;
}

void finish(const StudyOptions& options, const std::string& kind, const std::string& csv) {
  if (!is_job_root()) return;  // rank 0 writes
  const std::string csv_path = output_of(options, kind, ".csv").string();
  write_file_atomically(csv_path, csv);
  fmt::print("wrote {}\n", csv_path);
  if (options.no_plot) return;
  const std::string png_path = output_of(options, kind, ".png").string();
  run_python_script("plot_study.py", png_path, [&](const std::string& drawing) {
    return std::vector<std::string>{kind, csv_path, drawing};
  });
  fmt::print("wrote {}\n", png_path);
}

StudySettings settings_of(const StudyOptions& options, ProgressBar& bar, std::size_t index, std::size_t count) {
  StudySettings settings;
  settings.episodes = options.episodes;
  settings.seed = options.seed;
  settings.threads = options.threads;
  settings.ranks = job_ranks();
  settings.searcher = options.searcher;
  settings.reference = options.reference;
  settings.parameters = options.allocator.values();
  settings.progress = [&bar, index, count](std::uint64_t done, std::uint64_t total) {
    bar.update(index * total + done, count * total);
  };
  return settings;
}

void run_compute_time(const StudyOptions& options) {
  const std::vector<Problem> problems = prepare(options, "compute-time");
  std::string csv =
      "instance,solver,episodes,success_rate,ci95,mean_episode_seconds,median_episode_seconds,"
      "p99_episode_seconds,mean_decision_seconds,iterations_per_search\n";
  ProgressBar bar("study compute-time");
  for (std::size_t i = 0; i < problems.size(); ++i) {
    const Mdp mdp(problems[i]);
    const ComputeTimeStudy study = compute_time_study(mdp, settings_of(options, bar, i, problems.size()));
    for (const auto& [solver, result] :
         {std::pair{options.searcher, &study.searcher}, std::pair{options.reference, &study.reference}}) {
      csv += fmt::format("{},{},{},{},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.6g}\n", label_of(options.instances[i]), solver,
                         result->episodes, result->success_rate, result->ci95,
                         result->episode_decision_time.mean_us * 1e-6, result->episode_decision_time.median_us * 1e-6,
                         result->episode_decision_time.p99_us * 1e-6, result->decision_time.mean_us * 1e-6,
                         iterations_per_search(solver, *result));
    }
  }
  finish(options, "compute-time", csv);
}

void run_equal_time(const StudyOptions& options) {
  const std::vector<Problem> problems = prepare(options, "equal-time");
  std::string csv =
      "instance,episodes,dp_rerun_decision_seconds,dp_rerun_success_rate,dp_rerun_ci95,mcts_success_rate,"
      "mcts_ci95,mcts_iterations_per_search\n";
  ProgressBar bar("study equal-time");
  for (std::size_t i = 0; i < problems.size(); ++i) {
    const Mdp mdp(problems[i]);
    const EqualTimeStudy study = equal_time_study(mdp, settings_of(options, bar, i, problems.size()));
    csv += fmt::format("{},{},{:.9g},{},{},{},{},{:.6g}\n", label_of(options.instances[i]), options.episodes,
                       study.reference_decision_seconds, study.reference.success_rate, study.reference.ci95,
                       study.searcher.success_rate, study.searcher.ci95,
                       iterations_per_search(options.searcher, study.searcher));
  }
  finish(options, "equal-time", csv);
}

void run_anytime(const StudyOptions& options) {
  const std::vector<double> multipliers = parse_multipliers(options.multipliers);
  const std::vector<Problem> problems = prepare(options, "anytime");
  std::string csv =
      "instance,episodes,log10_multiplier,seconds_per_decision,success_rate,ci95,iterations_per_search,"
      "dp_rerun_decision_seconds,dp_rerun_success_rate,optimum\n";
  ProgressBar bar("study anytime");
  for (std::size_t i = 0; i < problems.size(); ++i) {
    const Mdp mdp(problems[i]);
    const AnytimeStudy study = anytime_study(mdp, multipliers, settings_of(options, bar, i, problems.size()));
    for (const AnytimePoint& point : study.points) {
      csv +=
          fmt::format("{},{},{},{:.9g},{},{},{:.6g},{:.9g},{},{}\n", label_of(options.instances[i]), options.episodes,
                      point.log10_multiplier, point.seconds_per_decision, point.searcher.success_rate,
                      point.searcher.ci95, iterations_per_search(options.searcher, point.searcher),
                      study.reference_decision_seconds, study.reference.success_rate, study.optimum);
    }
  }
  finish(options, "anytime", csv);
}

}  // namespace

void add_study_command(CLI::App& app) {
  CLI::App* study = app.add_subcommand("study", "Computation-time studies of mcts against dp-rerun (Figs. 4-6)");
  study->require_subcommand(1);
  const auto add = [study](const std::string& name, const std::string& description, void (*run)(const StudyOptions&)) {
    auto options = std::make_shared<StudyOptions>();
    CLI::App* command = study->add_subcommand(name, description);
    command->add_option("INSTANCE", options->instances, "Instance files (JSON, SPEC §5)")->required();
    command->add_option("--out", options->out, "Directory for the CSV and PNG")->capture_default_str();
    add_number_option(*command, "--episodes", options->episodes, "Episodes per evaluated configuration",
                      std::uint64_t{1});
    add_number_option(*command, "--seed", options->seed, "Seed of the hidden worlds");
    add_threads_option(*command, options->threads, "Worker threads (0: one per hardware thread)");
    command->add_flag("--no-plot", options->no_plot, "Write the CSV only");
    command
        ->add_option("--searcher", options->searcher,
                     "The anytime allocator studied (" +
                         fmt::format("{}", fmt::join(allocator_registry().names({Capability::anytime}), ", ")) + ")")
        ->capture_default_str();
    command
        ->add_option("--reference", options->reference,
                     "The stationary allocator it is measured against (its time per decision sets the searcher's)")
        ->capture_default_str();
    if (name == "anytime") {
      command
          ->add_option("--log10-multipliers", options->multipliers,
                       "Comma-separated exponents m: mcts gets 10^m times dp-rerun's time per decision")
          ->capture_default_str();
    }
    options->allocator.add_to(*command);
    command->callback([options, run] { run(*options); });
  };
  add("compute-time", "Fig. 4: total decision time per episode, mcts (--iterations) against dp-rerun",
      run_compute_time);
  add("equal-time", "Fig. 5: mcts given exactly dp-rerun's measured time per decision", run_equal_time);
  add("anytime", "Fig. 6: mcts success against log10 of a multiplier of dp-rerun's time", run_anytime);
}

}  // namespace ontime::cli
