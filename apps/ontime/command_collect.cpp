// `ontime collect --domain NAME --trials N`: refines every action of the domain's skeleton tree
// N times with the real motion planner, writes the planner log and fits the instance. Every
// finished trial goes to a checkpoint first, so that an interrupted collection can be resumed
// (--resume) with the same result; the checkpoint is deleted once the outputs are written.
// With --every-action: every action the domain can refine instead, each on its own. The
// collection and the fit are domains::collect_and_fit (collect_and_fit.hpp), the output the
// domains report's.

#include <fmt/format.h>

#include <filesystem>

#include "cluster_job.hpp"
#include "common.hpp"
#include "data_paths.hpp"
#include "memory_limits.hpp"
#include "number_options.hpp"
#include "ontime/domains/collect_and_fit.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/domains/report.hpp"
#include "output_paths.hpp"

namespace ontime::cli {
namespace {

// --log-format ompl-benchmark: the default log is data/logs/DOMAIN.log, its time limit the cut-off.
std::filesystem::path default_log_file(const std::string& domain, const std::string& format) {
  std::filesystem::path path = collected_log_file(domain);
  return format == "ompl-benchmark" ? path.replace_extension(".log") : path;
}

}  // namespace

void add_collect_command(CLI::App& app) {
  struct Options {
    std::string domain;
    std::string world;
    std::string log;
    std::string instance;
    std::string checkpoint;
    std::string effort = "checks";
    std::string log_format = "jsonl";
    std::uint64_t trials = 1000;
    std::uint64_t seed = 1;
    unsigned threads = 0;
    double step_seconds = 0;
    Steps deadline = 0;
    Steps budget = 0;
    double checks_per_second = 0;
    double laplace = 0;
    bool resume = false;
    bool every_action = false;
    bool features = false;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  std::string names;
  for (const std::string& name : domains::domain_names()) names += (names.empty() ? "" : ", ") + name;
  CLI::App* command =
      app.add_subcommand("collect", "Refine every action of a domain many times, log it, fit the instance");
  command->add_option("--domain", options->domain, "Domain: " + names)->required();
  command->add_option("--world", options->world, "World file (default: data/domains/DOMAIN.json)");
  add_number_option(*command, "--trials", options->trials, "Attempts per action", std::uint64_t{1});
  add_number_option(*command, "--seed", options->seed, "Seed (trial t of action a uses stream t of stream a)");
  add_threads_option(*command, options->threads,
                     "Worker threads (0: one per hardware thread); the log does not depend on it");
  command->add_option("--effort", options->effort, "Effort unit: checks (deterministic) or wall (wall-clock seconds)")
      ->check(CLI::IsMember({"checks", "wall"}))
      ->capture_default_str();
  add_number_option(*command, "--step", options->step_seconds, "Seconds of effort per step (default: the world file's)",
                    kPositive, std::numeric_limits<double>::max(), false);
  add_number_option(*command, "--deadline", options->deadline, "Deadline D in steps (default: the world file's)",
                    Steps{1}, Problem::kMaxDeadline, false);
  add_number_option(*command, "--budget", options->budget,
                    "Steps of effort after which an attempt is cut off (default: D)", Steps{1},
                    std::numeric_limits<Steps>::max(), false);
  add_number_option(*command, "--checks-per-second", options->checks_per_second,
                    "Nominal collision checks per second of the checks unit (default: the world file's)", kPositive,
                    std::numeric_limits<double>::max(), false);
  add_number_option(*command, "--laplace", options->laplace, "Laplace smoothing of the fit", 0.0);
  command->add_option("--log", options->log,
                      "Planner log to write (default: data/logs/DOMAIN.jsonl in the current directory)");
  command->add_option("--log-format", options->log_format, "Log format: jsonl or ompl-benchmark (then DOMAIN.log)")
      ->check(CLI::IsMember({"jsonl", "ompl-benchmark"}))
      ->capture_default_str();
  command->add_option(
      "-o,--instance", options->instance,
      "Instance to write (default: data/instances/DOMAIN.json in the current directory, where run looks first)");
  command->add_option("--checkpoint", options->checkpoint,
                      "Journal of finished trials, kept until the outputs are written (default: LOG.checkpoint)");
  command->add_flag("--resume", options->resume,
                    "Continue the collection recorded in the checkpoint, if there is one (same settings, same result)");
  command->add_flag("--every-action", options->every_action,
                    "Refine every action of the domain on its own (navigation: every doorway move, both ways) "
                    "instead of the skeletons' actions; the instance gets one skeleton per action");
  command->add_flag("--features", options->features,
                    "Every log record carries the world (the world file's name) and the action's feature vector "
                    "there, for conditional time models (docs/learning.md)");
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    const std::filesystem::path world =
        options->world.empty() ? default_world_file(options->domain) : std::filesystem::path(options->world);
    const domains::LoadedDomain loaded = domains::load_domain(options->domain, world);
    domains::CollectAndFitOptions collect;
    collect.trials = options->trials;
    collect.seed = options->seed;
    collect.threads = options->threads;
    collect.effort = options->effort;
    collect.checks_per_second = options->checks_per_second;
    collect.step_seconds = options->step_seconds;
    collect.deadline = options->deadline;
    collect.budget = options->budget;
    collect.laplace = options->laplace;
    collect.every_action = options->every_action;
    collect.features = options->features;
    collect.log_format = options->log_format;
    collect.log = options->log.empty() ? default_log_file(options->domain, options->log_format)
                                       : std::filesystem::path(options->log);
    collect.instance =
        options->instance.empty() ? collected_instance_file(options->domain) : std::filesystem::path(options->instance);
    collect.checkpoint = options->checkpoint;
    collect.resume = options->resume;
    collect.ranks = job_ranks();
    // The checkpoint is read back on --resume, but it is the collection's own file, not an input.
    check_outputs(
        {{"--log", collect.log}, {"--instance", collect.instance}, {"--checkpoint", domains::checkpoint_path(collect)}},
        {world}, MissingFolder::create);
    ProgressBar bar("collect " + options->domain);
    collect.progress = [&bar](std::uint64_t done, std::uint64_t total) { bar.update(done, total); };
    const domains::CollectAndFitResult result =
        domains::collect_and_fit(*loaded.domain, loaded.defaults, world, collect, flag_spelling());
    if (!result.fit) return;  // another rank than the one that writes and prints
    const domains::report::Collection report{
        .domain = options->domain, .world = world.string(), .options = &collect, .result = &result};
    fmt::print("{}", options->json ? domains::report::to_json(report) + "\n" : domains::report::to_text(report));
  });
}

}  // namespace ontime::cli
