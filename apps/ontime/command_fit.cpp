// `ontime fit LOG --step S --deadline D --skeletons FILE --output INSTANCE`: learns each
// action's planning and execution distributions from a planner log and writes the instance.
// With --library instead of --skeletons: every action of the log, one skeleton each (a library
// of per-action distributions, e.g. of `collect --every-action`).

#include <fmt/format.h>

#include <filesystem>

#include "common.hpp"
#include "fit_report.hpp"
#include "number_options.hpp"
#include "ontime/error.hpp"
#include "ontime/fitting.hpp"
#include "ontime/instance_io.hpp"
#include "ontime/planner_log.hpp"
#include "output_paths.hpp"

namespace ontime::cli {

void add_fit_command(CLI::App& app) {
  struct Options {
    std::string log;
    std::string skeletons;
    std::string output;
    std::string name;
    std::string description;
    double step_seconds = 1.0;
    Steps deadline = 0;
    double laplace = 0;
    bool library = false;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("fit", "Learn an instance's time distributions from a planner log");
  command->add_option("LOG", options->log, "Planner log (JSON Lines, docs/formats.md)")->required();
  add_number_option(*command, "--step", options->step_seconds,
                    "Length of one step in seconds (times are rounded up to steps)", kPositive,
                    std::numeric_limits<double>::max(), false)
      ->required();
  add_number_option(*command, "--deadline", options->deadline,
                    "Deadline D in steps; planning or execution beyond it is \"never\"", Steps{1},
                    Problem::kMaxDeadline, false)
      ->required();
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
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    if (options->skeletons.empty() && !options->library) throw UsageError("give --skeletons FILE or --library");
    SkeletonList skeletons;
    if (!options->library) skeletons = load_skeleton_file(options->skeletons);
    const std::vector<RefinementAttempt> attempts = load_planner_log(options->log);
    if (options->library) skeletons = single_action_skeletons(attempts, options->log);
    std::vector<std::filesystem::path> inputs{options->log};
    if (!options->library) inputs.emplace_back(options->skeletons);
    check_outputs({{"--output", options->output}}, inputs);
    FitOptions fit_options;
    fit_options.step_seconds = options->step_seconds;
    fit_options.deadline = options->deadline;
    fit_options.laplace = options->laplace;
    fit_options.name = options->name.empty() ? std::filesystem::path(options->output).stem().string() : options->name;
    fit_options.description = options->description;
    const FitResult fit = fit_problem(attempts, options->log, skeletons, fit_options);
    save_problem(fit.problem, options->output);
    if (options->json) {
      Json out;
      out["log"] = options->log;
      out["records"] = attempts.size();
      out["instance"] = options->output;
      out["deadline"] = options->deadline;
      out["step_seconds"] = options->step_seconds;
      out["laplace"] = options->laplace;
      out["actions"] = fit_report_json(fit);
      print_json(out);
      return;
    }
    fmt::print("Fitted {} from {} records of {}: deadline {} steps of {} s, Laplace alpha {}.\n\n", options->output,
               attempts.size(), options->log, options->deadline, options->step_seconds, options->laplace);
    fmt::print("{}", fit_report_markdown(fit));
    fmt::print("\nT: planning steps, X: execution steps (means over the steps within the deadline).\n");
  });
}

}  // namespace ontime::cli
