#include "ontime/domains/collect_and_fit.hpp"

#include <fmt/format.h>

#include "ontime/domains/collection_journal.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/model/ompl_benchmark_log.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/input_file.hpp"

namespace ontime::domains {
namespace {

OmplLogWriteOptions ompl_log_options(const std::string& domain, const CollectionOptions& collection) {
  OmplLogWriteOptions options;
  options.experiment = domain;
  options.time_limit_seconds = static_cast<double>(collection.budget_steps) * collection.step_seconds;
  options.seed = collection.seed;
  options.setup = fmt::format(
      "ontime collect --domain {}: {} trials per action, effort unit {}, step {} s, cut-off {} steps", domain,
      collection.trials, effort_unit_name(collection.effort.unit), collection.step_seconds, collection.budget_steps);
  return options;
}

}  // namespace

CollectionOptions collection_options(const DomainDefaults& defaults, const CollectAndFitOptions& options) {
  CollectionOptions collection;
  collection.trials = options.trials;
  collection.seed = options.seed;
  collection.threads = options.threads;
  collection.effort = effort_settings(defaults, options.effort, options.checks_per_second);
  collection.step_seconds = options.step_seconds > 0 ? options.step_seconds : defaults.collection.step_seconds;
  collection.budget_steps = options.budget > 0 ? options.budget : collection_deadline(defaults, options);
  collection.every_action = options.every_action;
  collection.features = options.features;
  collection.ranks = options.ranks;
  return collection;
}

Steps collection_deadline(const DomainDefaults& defaults, const CollectAndFitOptions& options) {
  return options.deadline > 0 ? options.deadline : defaults.collection.deadline;
}

std::filesystem::path checkpoint_path(const CollectAndFitOptions& options) {
  return options.checkpoint.empty() ? std::filesystem::path(options.log.string() + ".checkpoint") : options.checkpoint;
}

CollectAndFitResult collect_and_fit(const Domain& domain, const DomainDefaults& defaults,
                                    const std::filesystem::path& world, const CollectAndFitOptions& options,
                                    const ParameterSpelling& spelling) {
  if (options.log_format != "jsonl" && options.log_format != "ompl-benchmark") {
    static const std::string kFormats[] = {"jsonl", "ompl-benchmark"};
    throw unknown_name_error("log format", options.log_format, kFormats);
  }
  if (options.features && options.log_format != "jsonl") {
    throw UsageError("feature vectors are written only to a jsonl log (OMPL's benchmark format has no place for them)");
  }
  CollectAndFitResult out;
  out.collection = collection_options(defaults, options);
  out.collection.world_name = world.stem().string();
  out.deadline = collection_deadline(defaults, options);
  out.checkpoint = checkpoint_path(options);
  // The journal refuses this too; this refusal names the parameter that resumes.
  if (!options.resume && !CollectionJournal::parts(out.checkpoint).empty()) {
    throw UsageError(CollectionJournal::parts(out.checkpoint).front().string() +
                     ": the checkpoint of an unfinished collection is there; resume it (" +
                     spell_parameter(spelling, "resume") + ") or delete it");
  }
  CollectionOptions collection = out.collection;
  CollectionJournal journal(out.checkpoint, domain, collection, read_input_file(world, "world"), options.resume,
                            collection.ranks);
  collection.journal = &journal;
  collection.progress = options.progress;
  out.resumed_attempts = journal.finished().size();
  out.result = collect(domain, collection);
  for (const RefinementAttempt& attempt : out.result.log) out.found += attempt.found ? 1 : 0;
  if (!is_root_rank(collection.ranks)) {  // the root rank writes the outputs, then every rank's checkpoint goes
    journal.remove();
    return out;
  }
  if (options.log_format == "ompl-benchmark") {
    save_ompl_benchmark_log(out.result.log, options.log, ompl_log_options(domain.name(), collection));
  } else {
    save_planner_log(out.result.log, options.log);
  }
  FitOptions fit;
  fit.step_seconds = collection.step_seconds;
  fit.deadline = out.deadline;
  fit.laplace = options.laplace;
  fit.name = domain.name();
  fit.description = fmt::format(
      "Fitted from {} attempts per action of the {} domain ({}): seed {}, effort unit {}{}, step {} s, cut-off {} "
      "steps",
      options.trials, domain.name(), world.filename().string(), options.seed, effort_unit_name(collection.effort.unit),
      collection.effort.unit == EffortUnit::collision_checks
          ? fmt::format(" at {} checks per second", collection.effort.checks_per_second)
          : std::string(),
      collection.step_seconds, collection.budget_steps);
  const SkeletonList skeletons = options.every_action ? single_action_skeletons(out.result.log, options.log.string())
                                                      : SkeletonList{world.string(), domain.skeletons()};
  out.fit = fit_problem(out.result.log, options.log.string(), skeletons, fit);
  save_problem(out.fit->problem, options.instance);
  journal.remove();
  return out;
}

}  // namespace ontime::domains
