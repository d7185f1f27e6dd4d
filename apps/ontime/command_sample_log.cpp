// `ontime sample-log INSTANCE --attempts N --seed S --output LOG`: a planner log drawn from an
// instance's own distributions, to check that `ontime fit` gives the instance back.

#include <fmt/format.h>

#include "common.hpp"
#include "ontime/instance_io.hpp"
#include "ontime/log_sampling.hpp"
#include "ontime/planner_log.hpp"
#include "output_paths.hpp"

namespace ontime::cli {

void add_sample_log_command(CLI::App& app) {
  struct Options {
    std::string instance;
    std::string output;
    LogSamplingOptions sampling;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("sample-log", "Draw a planner log from an instance's distributions");
  command->add_option("INSTANCE", options->instance, "Instance file (JSON, SPEC §5)")->required();
  command->add_option("-o,--output", options->output, "Planner log to write (JSON Lines)")->required();
  command->add_option("--attempts", options->sampling.attempts_per_action, "Attempts per action")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--seed", options->sampling.seed, "Seed (attempt i of action a uses stream i of stream a)")
      ->capture_default_str();
  command->add_option("--cutoff", options->sampling.cutoff_steps,
                      "Steps of effort after which an attempt is cut off (default: the deadline)")
      ->check(CLI::PositiveNumber);
  command->callback([options] {
    const Problem problem = load_problem(options->instance);
    check_outputs({{"--output", options->output}}, {options->instance});
    const std::vector<RefinementAttempt> log = sample_planner_log(problem, options->sampling);
    save_planner_log(log, options->output);
    fmt::print("Wrote {} records ({} attempts per action, seed {}) to {}.\n", log.size(),
               options->sampling.attempts_per_action, options->sampling.seed, options->output);
  });
}

}  // namespace ontime::cli
