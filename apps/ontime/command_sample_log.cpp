// `ontime sample-log INSTANCE --attempts N --seed S --output LOG`: a planner log drawn from an
// instance's own distributions, to check that `ontime fit` gives the instance back.

#include <fmt/format.h>

#include "common.hpp"
#include "number_options.hpp"
#include "ontime/learn/log_sampling.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/util/atomic_file.hpp"
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
  add_number_option(*command, "--attempts", options->sampling.attempts_per_action, "Attempts per action",
                    std::uint64_t{1});
  add_number_option(*command, "--seed", options->sampling.seed,
                    "Seed (attempt i of action a uses stream i of stream a)");
  add_number_option(*command, "--cutoff", options->sampling.cutoff_steps,
                    "Steps of effort after which an attempt is cut off (default: the deadline)", Steps{1},
                    std::numeric_limits<Steps>::max(), false);
  command->callback([options] {
    const Problem problem = load_problem(options->instance);
    check_outputs({{"--output", options->output}}, {options->instance});
    const std::uint64_t records = write_sampled_planner_log(problem, options->sampling, options->output);
    fmt::print("Wrote {} records ({} attempts per action, seed {}) to {}.\n", records,
               options->sampling.attempts_per_action, options->sampling.seed, options->output);
  });
}

}  // namespace ontime::cli
