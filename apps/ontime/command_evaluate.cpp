// `ontime evaluate INSTANCE --solver NAME`: Monte Carlo success rate with its 95% interval,
// decision latency, and optionally the exact success probability.

#include <fmt/format.h>

#include "common.hpp"
#include "memory_limits.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/model/instance_io.hpp"

namespace ontime::cli {

void add_evaluate_command(CLI::App& app) {
  struct Options {
    std::string instance;
    std::string solver;
    bool exact = false;
    bool json = false;
    bool no_timing = false;
    AllocatorFlags allocator;
    MonteCarloFlags monte_carlo;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("evaluate", "Success rate of one allocator over simulated episodes");
  command->add_option("INSTANCE", options->instance, "Instance file (JSON, SPEC §5)")->required();
  add_solver_option(*command, options->solver);
  command->add_flag("--exact", options->exact, "Also compute the exact success probability (no sampling)");
  command->add_flag("--json", options->json, "Print JSON");
  command->add_flag("--no-timing", options->no_timing,
                    "Leave out the decision times and the run time, so that the output depends only on the inputs "
                    "(the same seed gives the same bytes for any thread or rank count)");
  options->monte_carlo.add_to(*command);
  options->allocator.add_to(*command);
  command->callback([options] {
    check_solver_names({options->solver});
    const Problem problem = load_problem(options->instance);
    const Mdp mdp(problem);
    const ParameterValues parameters = options->allocator.values();
    options->monte_carlo.check_tree_memory(options->solver, parameters);
    if (options->exact || allocator_registry().find(options->solver).capabilities.has(Capability::optimal)) {
      check_state_cap_memory(problem, max_states_of(parameters), options->instance);
    }
    const AllocatorFactory factory = make_allocator_factory(options->solver, mdp, parameters);

    MonteCarloOptions monte_carlo = options->monte_carlo.options();
    monte_carlo.time_decisions = !options->no_timing;
    ProgressBar bar("evaluate " + options->solver);
    monte_carlo.progress = [&bar](std::uint64_t done, std::uint64_t total) { bar.update(done, total); };
    const MonteCarloResult result = run_monte_carlo(mdp, factory, monte_carlo);

    std::optional<ExactEvaluation> exact;
    if (options->exact) {
      const auto allocator = factory();
      exact = evaluate_exactly(mdp, *allocator, max_states_of(parameters));
    }
    if (options->json) {
      Json out;
      out["solver"] = options->solver;
      out["parameters"] = parameters_json(allocator_registry().find(options->solver), parameters);
      out["instance"] = options->instance;
      out["episodes"] = result.episodes;
      out["seed"] = options->monte_carlo.seed;
      out["successes"] = result.successes;
      out["success_rate"] = result.success_rate;
      out["ci95"] = result.ci95;
      if (!options->no_timing) {
        out["decision_time_us"] = {{"median", result.decision_time.median_us},
                                   {"p99", result.decision_time.p99_us},
                                   {"mean", result.decision_time.mean_us},
                                   {"max", result.decision_time.max_us},
                                   {"decisions", result.decision_time.decisions}};
        out["seconds"] = result.seconds;
      }
      if (exact) {
        out["exact_success_probability"] = exact->success_probability;
        out["exact_states"] = exact->states;
      }
      print_json(out);
      return;
    }
    fmt::print("solver          {}\n", options->solver);
    fmt::print("instance        {} ({}), deadline {}\n", options->instance, problem.name(), problem.deadline());
    fmt::print("success rate    {:.4f} ± {:.4f}  ({} of {} episodes, seed {})\n", result.success_rate, result.ci95,
               result.successes, result.episodes, options->monte_carlo.seed);
    if (exact) fmt::print("exact           {:.6f}  ({} states)\n", exact->success_probability, exact->states);
    if (options->no_timing) return;
    fmt::print("decision time   median {:.3f} µs, p99 {:.3f} µs, mean {:.3f} µs, max {:.3f} µs over {} decisions\n",
               result.decision_time.median_us, result.decision_time.p99_us, result.decision_time.mean_us,
               result.decision_time.max_us, result.decision_time.decisions);
  });
}

}  // namespace ontime::cli
