// `ontime solve INSTANCE`: the exact optimum by expectimax.

#include <fmt/core.h>

#include <chrono>

#include "common.hpp"
#include "memory_limits.hpp"
#include "number_options.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/instance_io.hpp"

namespace ontime::cli {

void add_solve_command(CLI::App& app) {
  struct Options {
    std::string instance;
    std::size_t max_states = OptimalSolver::kDefaultMaxStates;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("solve", "Exact optimal success probability and first choice (expectimax)");
  command->add_option("INSTANCE", options->instance, "Instance file (JSON, SPEC §5)")->required();
  add_number_option(*command, "--max-states", options->max_states, "Stop with an error past this many states",
                    std::size_t{1});
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    const Problem problem = load_problem(options->instance);
    check_state_cap_memory(problem, options->max_states, options->instance);
    const Mdp mdp(problem);
    const auto started = std::chrono::steady_clock::now();
    OptimalSolver solver(mdp, options->max_states);
    const double value = solver.solve(mdp.start());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const int first = solver.best_choice(mdp.start()).value_or(-1);
    const std::string first_action = first >= 0 ? problem.action(mdp.next_action(mdp.start(), first)).id : "";
    if (options->json) {
      Json out;
      out["instance"] = options->instance;
      out["name"] = problem.name();
      out["optimal_success_probability"] = value;
      out["states"] = solver.states();
      out["seconds"] = seconds;
      out["first_choice"] = first;
      out["first_action"] = first_action;
      print_json(out);
      return;
    }
    fmt::print("instance                     {} ({}), deadline {}, {} skeletons\n", options->instance, problem.name(),
               problem.deadline(), problem.skeleton_count());
    fmt::print("optimal success probability  {:.6f}\n", value);
    if (first >= 0) {
      fmt::print("first choice                 skeleton {} (refine {})\n", first, first_action);
    } else {
      fmt::print("first choice                 none (no skeleton can meet the deadline)\n");
    }
    fmt::print("states                       {}\n", solver.states());
    fmt::print("time                         {:.4f} s\n", seconds);
  });
}

}  // namespace ontime::cli
