// `ontime collect --domain NAME --trials N`: refines every action of the domain's skeleton tree
// N times with the real motion planner, writes the planner log and fits the instance. Every
// finished trial goes to a checkpoint first, so that an interrupted collection can be resumed
// (--resume) with the same result; the checkpoint is deleted once the outputs are written.
// With --every-action: every action the domain can refine instead, each on its own.

#include <fmt/format.h>

#include <filesystem>

#include "cluster_job.hpp"
#include "common.hpp"
#include "data_paths.hpp"
#include "number_options.hpp"
#include "ontime/domains/collection.hpp"
#include "ontime/domains/collection_journal.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/learn/fitting.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/model/ompl_benchmark_log.hpp"
#include "ontime/report/report.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/input_file.hpp"
#include "output_paths.hpp"

namespace ontime::cli {
namespace {

// --log-format ompl-benchmark: the default log is data/logs/DOMAIN.log, its time limit the cut-off.
std::filesystem::path default_log_file(const std::string& domain, const std::string& format) {
  std::filesystem::path path = collected_log_file(domain);
  return format == "ompl-benchmark" ? path.replace_extension(".log") : path;
}

OmplLogWriteOptions ompl_log_options(const std::string& domain, const domains::CollectionOptions& collection) {
  OmplLogWriteOptions options;
  options.experiment = domain;
  options.time_limit_seconds = static_cast<double>(collection.budget_steps) * collection.step_seconds;
  options.seed = collection.seed;
  options.setup =
      fmt::format("ontime collect --domain {}: {} trials per action, effort unit {}, step {} s, cut-off {} steps",
                  domain, collection.trials, domains::effort_unit_name(collection.effort.unit), collection.step_seconds,
                  collection.budget_steps);
  return options;
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
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    const std::filesystem::path world =
        options->world.empty() ? default_world_file(options->domain) : std::filesystem::path(options->world);
    const domains::LoadedDomain loaded = domains::load_domain(options->domain, world);
    const domains::CollectionDefaults& defaults = loaded.defaults.collection;
    const std::filesystem::path log_path = options->log.empty() ? default_log_file(options->domain, options->log_format)
                                                                : std::filesystem::path(options->log);
    const std::filesystem::path instance_path =
        options->instance.empty() ? collected_instance_file(options->domain) : std::filesystem::path(options->instance);

    domains::CollectionOptions collection;
    collection.trials = options->trials;
    collection.seed = options->seed;
    collection.threads = options->threads;
    collection.effort.unit = domains::parse_effort_unit(options->effort);
    collection.effort.checks_per_second =
        options->checks_per_second > 0 ? options->checks_per_second : defaults.checks_per_second;
    collection.step_seconds = options->step_seconds > 0 ? options->step_seconds : defaults.step_seconds;
    const Steps deadline = options->deadline > 0 ? options->deadline : defaults.deadline;
    collection.budget_steps = options->budget > 0 ? options->budget : deadline;
    collection.every_action = options->every_action;
    collection.ranks = job_ranks();
    const std::filesystem::path checkpoint_path = options->checkpoint.empty()
                                                      ? std::filesystem::path(log_path.string() + ".checkpoint")
                                                      : std::filesystem::path(options->checkpoint);
    // The checkpoint is read back on --resume, but it is the collection's own file, not an input.
    check_outputs({{"--log", log_path}, {"--instance", instance_path}, {"--checkpoint", checkpoint_path}}, {world},
                  MissingFolder::create);
    // The journal refuses this too; the command's refusal names the option that resumes.
    if (!options->resume && !domains::CollectionJournal::parts(checkpoint_path).empty()) {
      throw UsageError(domains::CollectionJournal::parts(checkpoint_path).front().string() +
                       ": the checkpoint of an unfinished collection is there; resume it (--resume) or delete it");
    }
    domains::CollectionJournal journal(checkpoint_path, *loaded.domain, collection, read_input_file(world, "world"),
                                       options->resume, collection.ranks);
    collection.journal = &journal;
    const std::size_t resumed = journal.finished().size();
    ProgressBar bar("collect " + options->domain);
    collection.progress = [&bar](std::uint64_t done, std::uint64_t total) { bar.update(done, total); };
    const domains::CollectionResult result = domains::collect(*loaded.domain, collection);
    if (!is_job_root()) {  // rank 0 writes the outputs, then every rank's checkpoint goes
      journal.remove();
      return;
    }

    if (options->log_format == "ompl-benchmark") {
      save_ompl_benchmark_log(result.log, log_path, ompl_log_options(options->domain, collection));
    } else {
      save_planner_log(result.log, log_path);
    }
    FitOptions fit_options;
    fit_options.step_seconds = collection.step_seconds;
    fit_options.deadline = deadline;
    fit_options.laplace = options->laplace;
    fit_options.name = options->domain;
    fit_options.description = fmt::format(
        "Fitted from {} attempts per action of the {} domain ({}): seed {}, effort unit {}{}, step {} s, cut-off {} "
        "steps",
        options->trials, options->domain, world.filename().string(), options->seed, options->effort,
        collection.effort.unit == domains::EffortUnit::collision_checks
            ? fmt::format(" at {} checks per second", collection.effort.checks_per_second)
            : std::string(),
        collection.step_seconds, collection.budget_steps);
    const SkeletonList skeletons = options->every_action ? single_action_skeletons(result.log, log_path.string())
                                                         : SkeletonList{world.string(), loaded.domain->skeletons()};
    const FitResult fit = fit_problem(result.log, log_path.string(), skeletons, fit_options);
    save_problem(fit.problem, instance_path);
    journal.remove();

    std::uint64_t found = 0;
    for (const RefinementAttempt& attempt : result.log) found += attempt.found ? 1 : 0;
    if (options->json) {
      Json out;
      out["domain"] = options->domain;
      out["world"] = world.string();
      out["trials"] = options->trials;
      out["every_action"] = options->every_action;
      out["seed"] = options->seed;
      out["effort"] = options->effort;
      out["step_seconds"] = collection.step_seconds;
      out["deadline"] = deadline;
      out["budget_steps"] = collection.budget_steps;
      out["checks_per_second"] = collection.effort.checks_per_second;
      out["attempts"] = result.log.size();
      out["found"] = found;
      out["collision_checks"] = result.collision_checks;
      out["seconds"] = result.seconds;
      out["resumed_attempts"] = resumed;
      out["log"] = log_path.string();
      out["instance"] = instance_path.string();
      out["actions"] = Json::parse(report::fit_json(fit));
      print_json(out);
      return;
    }
    fmt::print("Collected {} attempts ({} per action, {} found) in {:.1f} s: {} collision checks.\n", result.log.size(),
               options->trials, found, result.seconds, result.collision_checks);
    if (resumed > 0) fmt::print("Resumed from {}: {} attempts were done before.\n", checkpoint_path.string(), resumed);
    fmt::print("Log: {}. Instance: {} (deadline {} steps of {} s).\n\n", log_path.string(), instance_path.string(),
               deadline, collection.step_seconds);
    fmt::print("{}", report::fit_markdown(fit));
    fmt::print("\nT: planning steps, X: execution steps (means over the steps within the deadline).\n");
  });
}

}  // namespace ontime::cli
