// `ontime fit LOG --step S --deadline D --skeletons FILE --output INSTANCE`: learns each
// action's planning and execution distributions from a planner log and writes the instance.
// The log is JSON Lines, or (--format ompl-benchmark) one or more OMPL benchmark logs. With
// --library instead of --skeletons: every action of the logs, one skeleton each (a library of
// per-action distributions, e.g. of `collect --every-action`).
//
// `ontime fit LOG... --conditional KIND --step S --output MODEL`: a conditional time model
// (learn/conditional_model.hpp) from logs whose records carry features (`collect --features`,
// one log per world or one for many), for `ontime predict`.

#include <fmt/format.h>

#include <filesystem>
#include <optional>
#include <vector>

#include "common.hpp"
#include "number_options.hpp"
#include "ontime/learn/conditional_model.hpp"
#include "ontime/learn/fitting.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/model/ompl_benchmark_log.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/report/conditional_report.hpp"
#include "ontime/report/report.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "output_paths.hpp"
#if ONTIME_WITH_DOMAINS
#include "ontime/domains/registry.hpp"
#endif

namespace ontime::cli {
namespace {

struct LogOptions {
  std::vector<std::string> logs;
  std::string format = "jsonl";
  double speed = 0;
  std::vector<std::string> actions;
  std::string mapping;
};

// Refuses options that do not fit the log format, before any log is read.
void check_log_options(const LogOptions& options) {
  if (options.format == "jsonl") {
    if (options.logs.size() != 1)
      throw UsageError("--format jsonl reads one LOG (got " + std::to_string(options.logs.size()) + ")");
    if (options.speed > 0 || !options.actions.empty() || !options.mapping.empty()) {
      throw UsageError("--speed, --action and --mapping are options of --format ompl-benchmark");
    }
    return;
  }
  if (!(options.speed > 0)) throw UsageError("--format ompl-benchmark needs --speed (path length per second)");
  if (!options.actions.empty() && !options.mapping.empty()) {
    throw UsageError("give either --action (one per LOG) or --mapping, not both");
  }
  if (!options.actions.empty() && options.actions.size() != options.logs.size()) {
    throw UsageError("--action is given " + std::to_string(options.actions.size()) + " times for " +
                     std::to_string(options.logs.size()) + " LOG files: give one per LOG, in the same order");
  }
  for (const std::string& action : options.actions) {
    if (action.empty()) throw UsageError("--action must be a non-empty action id");
  }
}

std::vector<RefinementAttempt> load_logs(const LogOptions& options) {
  if (options.format == "jsonl") return load_planner_log(options.logs.front());
  std::optional<OmplActionMapping> mapping;
  if (!options.mapping.empty()) mapping = load_ompl_action_mapping(options.mapping);
  std::vector<RefinementAttempt> attempts;
  for (std::size_t i = 0; i < options.logs.size(); ++i) {
    OmplLogReadOptions read;
    read.speed = options.speed;
    if (!options.actions.empty()) read.action = options.actions[i];
    if (mapping) read.mapping = &*mapping;
    std::vector<RefinementAttempt> runs = load_ompl_benchmark_log(options.logs[i], read).attempts;
    attempts.insert(attempts.end(), std::make_move_iterator(runs.begin()), std::make_move_iterator(runs.end()));
  }
  return attempts;
}

struct ConditionalOptions {
  std::string kind;
  std::string domain;
  Steps horizon = 0;
  double ridge = ConditionalFitOptions{}.ridge;
  int bins = 0;
  int trees = ConditionalFitOptions{}.trees;
  int depth = ConditionalFitOptions{}.depth;
  double learning_rate = ConditionalFitOptions{}.learning_rate;
  double min_child_weight = ConditionalFitOptions{}.min_child_weight;
  std::string aft_distribution = ConditionalFitOptions{}.aft_distribution;
  double aft_scale = ConditionalFitOptions{}.aft_scale;
};

// fit --conditional: every LOG is JSON Lines with features; the model file is written atomically.
void fit_conditional(const LogOptions& log, const ConditionalOptions& conditional, double step_seconds,
                     const std::string& output, bool json) {
  if (log.format != "jsonl") throw UsageError("--conditional reads JSON Lines logs (--format jsonl)");
  ConditionalFitOptions options;
  options.kind = conditional.kind;
  options.horizon = conditional.horizon;
  options.ridge = conditional.ridge;
  options.bins = conditional.bins;
  options.trees = conditional.trees;
  options.depth = conditional.depth;
  options.learning_rate = conditional.learning_rate;
  options.min_child_weight = conditional.min_child_weight;
  options.aft_distribution = conditional.aft_distribution;
  options.aft_scale = conditional.aft_scale;
  if (!conditional.domain.empty()) {
#if ONTIME_WITH_DOMAINS
    options.feature_names = domains::domain_feature_names(conditional.domain);
#else
    throw UsageError("--domain needs the domains build (this ontime was built with ONTIME_BUILD_DOMAINS=OFF)");
#endif
  }
  std::vector<std::filesystem::path> inputs(log.logs.begin(), log.logs.end());
  check_outputs({{"--output", output}}, inputs);
  const ConditionalData data =
      load_conditional_data(std::vector<std::filesystem::path>(log.logs.begin(), log.logs.end()), step_seconds);
  const std::unique_ptr<ConditionalTimeModel> model = fit_conditional_model(data, options);
  write_file_atomically(output, model->to_json());
  if (json) {
    print_json(Json::parse(report::conditional_fit_json(*model, data, output)));
    return;
  }
  fmt::print("{}", report::conditional_fit_text(*model, data, output));
}

}  // namespace

void add_fit_command(CLI::App& app) {
  struct Options {
    LogOptions log;
    std::string skeletons;
    std::string output;
    std::string name;
    std::string description;
    double step_seconds = 1.0;
    Steps deadline = 0;
    double laplace = 0;
    bool library = false;
    bool json = false;
    ConditionalOptions conditional;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("fit", "Learn an instance's time distributions from a planner log");
  command->add_option("LOG", options->log.logs, "Planner log (JSON Lines; OMPL benchmark logs: one or more)")
      ->required();
  command->add_option("--format", options->log.format, "Log format: jsonl or ompl-benchmark (docs/formats.md)")
      ->check(CLI::IsMember({"jsonl", "ompl-benchmark"}))
      ->capture_default_str();
  add_number_option(*command, "--speed", options->log.speed,
                    "ompl-benchmark: path length per second of execution (execution time = solution length / speed)",
                    kPositive, std::numeric_limits<double>::max(), false);
  command->add_option("--action", options->log.actions,
                      "ompl-benchmark: the action id of every run of a LOG; once per LOG, in order");
  command->add_option("--mapping", options->log.mapping,
                      "ompl-benchmark: JSON file mapping experiment and planner names to action ids");
  add_number_option(*command, "--step", options->step_seconds,
                    "Length of one step in seconds (times are rounded up to steps)", kPositive,
                    std::numeric_limits<double>::max(), false)
      ->required();
  add_number_option(*command, "--deadline", options->deadline,
                    "Deadline D in steps; planning or execution beyond it is \"never\" (not with --conditional)",
                    Steps{1}, Problem::kMaxDeadline, false);
  CLI::Option* skeletons_option = command->add_option(
      "--skeletons", options->skeletons,
      "JSON file whose 'skeletons' member lists the plan skeletons (an instance or world file will do)");
  command
      ->add_flag("--library", options->library,
                 "Instead of --skeletons: every action of the log as a skeleton of its own, in the log's order")
      ->excludes(skeletons_option);
  command->add_option("-o,--output", options->output, "Instance file to write (SPEC §5)")->required();
  add_number_option(*command, "--laplace", options->laplace, "Laplace (add-alpha) smoothing of the estimates", 0.0);
  command->add_option("--name", options->name, "Instance name (default: the output file's stem)");
  command->add_option("--description", options->description, "Instance description");
  std::string kinds;
  for (const ConditionalModelKind& kind : conditional_model_kinds()) kinds += (kinds.empty() ? "" : ", ") + kind.name;
  command->add_option("--conditional", options->conditional.kind,
                      "Fit a conditional time model of this kind (" + kinds +
                          ") from logs with features, and write it to --output instead of an instance");
  command->add_option("--domain", options->conditional.domain,
                      "--conditional: the domain whose feature names the records carry (e.g. navigation)");
  add_number_option(*command, "--horizon", options->conditional.horizon,
                    "--conditional: steps predicted (0: the longest planning time of the logs)", Steps{0},
                    Problem::kMaxDeadline);
  add_number_option(*command, "--ridge", options->conditional.ridge,
                    "--conditional hazard: L2 penalty on the feature weights", 0.0, ConditionalFitOptions::kMaxRidge);
  add_number_option(*command, "--bins", options->conditional.bins,
                    "--conditional hazard: baseline hazard levels (0: one per step)", 0, Problem::kMaxDeadline);
  add_number_option(*command, "--trees", options->conditional.trees,
                    "--conditional boosted: boosting rounds (the trees of each booster)", 1, 10000);
  add_number_option(*command, "--depth", options->conditional.depth, "--conditional boosted: a tree's largest depth", 1,
                    16);
  add_number_option(*command, "--learning-rate", options->conditional.learning_rate,
                    "--conditional boosted: the shrinkage of each tree (XGBoost's eta)", kPositive, 1.0);
  add_number_option(*command, "--min-child-weight", options->conditional.min_child_weight,
                    "--conditional boosted: the least hessian sum of a leaf", 0.0);
  command
      ->add_option("--aft-distribution", options->conditional.aft_distribution,
                   "--conditional boosted: the law of log(planning time) of an attempt that finds (extreme: "
                   "Weibull times)")
      ->check(CLI::IsMember({"normal", "logistic", "extreme"}))
      ->capture_default_str();
  add_number_option(*command, "--aft-scale", options->conditional.aft_scale,
                    "--conditional boosted: the scale of that law", kPositive, 100.0);
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    if (!options->conditional.kind.empty()) {
      if (options->deadline != 0 || options->library || !options->skeletons.empty() || options->laplace != 0) {
        throw UsageError(
            "--conditional writes a model, not an instance: no --deadline, --skeletons, --library or "
            "--laplace");
      }
      fit_conditional(options->log, options->conditional, options->step_seconds, options->output, options->json);
      return;
    }
    if (options->deadline == 0) throw UsageError("--deadline is required (or --conditional KIND)");
    check_log_options(options->log);
    if (options->skeletons.empty() && !options->library) throw UsageError("give --skeletons FILE or --library");
    std::vector<std::filesystem::path> inputs(options->log.logs.begin(), options->log.logs.end());
    if (!options->library) inputs.emplace_back(options->skeletons);
    if (!options->log.mapping.empty()) inputs.emplace_back(options->log.mapping);
    SkeletonList skeletons;
    if (!options->library) skeletons = load_skeleton_file(options->skeletons);
    const std::vector<RefinementAttempt> attempts = load_logs(options->log);
    std::string logs;
    for (const std::string& log : options->log.logs) logs += (logs.empty() ? "" : ", ") + log;
    if (options->library) skeletons = single_action_skeletons(attempts, logs);
    check_outputs({{"--output", options->output}}, inputs);
    FitOptions fit_options;
    fit_options.step_seconds = options->step_seconds;
    fit_options.deadline = options->deadline;
    fit_options.laplace = options->laplace;
    fit_options.name = options->name.empty() ? std::filesystem::path(options->output).stem().string() : options->name;
    fit_options.description = options->description;
    const FitResult fit = fit_problem(attempts, logs, skeletons, fit_options);
    save_problem(fit.problem, options->output);
    if (options->json) {
      Json out;
      out["log"] = logs;
      out["format"] = options->log.format;
      out["records"] = attempts.size();
      out["instance"] = options->output;
      out["deadline"] = options->deadline;
      out["step_seconds"] = options->step_seconds;
      out["laplace"] = options->laplace;
      out["actions"] = Json::parse(report::fit_json(fit));
      print_json(out);
      return;
    }
    fmt::print("Fitted {} from {} records of {}: deadline {} steps of {} s, Laplace alpha {}.\n\n", options->output,
               attempts.size(), logs, options->deadline, options->step_seconds, options->laplace);
    fmt::print("{}", report::fit_markdown(fit));
    fmt::print("\nT: planning steps, X: execution steps (means over the steps within the deadline).\n");
  });
}

}  // namespace ontime::cli
