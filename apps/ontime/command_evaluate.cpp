// `ontime evaluate INSTANCE --solver NAME`: Monte Carlo success rate with its 95% interval,
// decision latency, and optionally the exact success probability.

#include <fmt/format.h>

#include <optional>

#include "common.hpp"
#include "memory_limits.hpp"
#include "ontime/allocators/belief_models.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/report/report.hpp"
#include "ontime/run/regret.hpp"
#include "ontime/util/error.hpp"

namespace ontime::cli {

namespace {

struct EvaluateOptions {
  std::string instance;
  std::string belief;
  std::string solver;
  std::string act;  // empty: the instance's own mode
  bool exact = false;
  bool regret = false;
  bool json = false;
  bool no_timing = false;
  AllocatorFlags allocator;
  MonteCarloFlags monte_carlo;
};

// The allocator's own instance under --belief: INSTANCE's skeletons with the belief's distributions.
std::optional<Problem> planned_problem(const EvaluateOptions& options, const Problem& problem) {
  if (options.belief.empty()) return std::nullopt;
  const Problem belief = load_problem(options.belief);
  try {
    return with_distributions_of(problem, belief);
  } catch (const UsageError& error) {
    throw UsageError(options.belief + ": " + error.what() + " (--belief against " + options.instance + ")");
  }
}

// Acting while planning (SPEC §10): the allocator's concurrent form in the same hidden worlds, with a
// belief deciding on the belief's model (ConcurrentBeliefModels).
void run_concurrent(const EvaluateOptions& options, const Problem& problem) {
  const std::optional<Problem> planned = planned_problem(options, problem);
  const ParameterValues parameters = options.allocator.values();
  options.monte_carlo.check_allocator_memory(options.solver, problem, parameters);
  if (options.exact || allocator_registry().find(options.solver).capabilities.has(Capability::optimal)) {
    check_exact_work(problem, max_states_of(parameters), options.instance, flag_spelling());
  }
  const ConcurrentBeliefModels models(problem, planned ? &*planned : nullptr);
  const ConcurrentMdp& mdp = models.world();
  const ConcurrentAllocatorFactory factory = models.factory(options.solver, parameters);
  MonteCarloOptions monte_carlo = options.monte_carlo.options();
  monte_carlo.time_decisions = !options.no_timing;
  ProgressBar bar("evaluate " + options.solver);
  monte_carlo.progress = [&bar](std::uint64_t done, std::uint64_t total) { bar.update(done, total); };
  const MonteCarloResult result = run_monte_carlo(
      mdp, options.regret ? with_regret(mdp, factory, max_states_of(parameters)) : factory, monte_carlo);
  std::optional<ExactEvaluation> exact;
  if (options.exact) {
    const auto allocator = factory();
    exact = evaluate_exactly(mdp, *allocator, max_states_of(parameters));
  }
  const report::Evaluation evaluation{.solver = options.solver,
                                      .parameters = parameters,
                                      .instance = options.instance,
                                      .problem = &problem,
                                      .belief = options.belief,
                                      .seed = options.monte_carlo.seed,
                                      .result = result,
                                      .exact = exact,
                                      .regret = options.regret ? regret_estimate(result.statistics) : std::nullopt,
                                      .timing = !options.no_timing};
  fmt::print("{}", options.json ? report::to_json(evaluation) + "\n" : report::to_text(evaluation));
}

}  // namespace

void add_evaluate_command(CLI::App& app) {
  using Options = EvaluateOptions;
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("evaluate", "Success rate of one allocator over simulated episodes");
  command->add_option("INSTANCE", options->instance, "Instance file (JSON, SPEC §5)")->required();
  add_solver_option(*command, options->solver);
  command->add_option("--belief", options->belief,
                      "Instance the allocator plans with (a prediction, a pooled fit): its distributions for "
                      "INSTANCE's actions, matched by id; the episodes and the exact value are drawn from INSTANCE");
  add_act_option(*command, options->act,
                 "Concurrent takes the allocators with a commit rule ('ontime allocators' names them)");
  command->add_flag("--exact", options->exact, "Also compute the exact success probability (no sampling)");
  command->add_flag("--regret", options->regret,
                    "Also estimate the regret V* - V (the optimum less the allocator's success probability) from the "
                    "exact loss of every decision of the episodes (performance-difference identity): far narrower than "
                    "the sampled rate's interval");
  command->add_flag("--json", options->json, "Print JSON");
  command->add_flag("--no-timing", options->no_timing,
                    "Leave out the decision times and the run time, so that the output depends only on the inputs "
                    "(the same seed gives the same bytes for any thread or rank count)");
  options->monte_carlo.add_to(*command);
  options->allocator.add_to(*command);
  command->callback([options] {
    check_solver_names({options->solver});
    Problem problem = load_problem(options->instance);
    if (!options->act.empty()) problem = problem.with_acting(*parse_acting(options->act));
    if (problem.acting() == Acting::concurrent) {
      run_concurrent(*options, problem);
      return;
    }
    const Mdp mdp(problem);
    const std::optional<Problem> planned = planned_problem(*options, problem);
    const Mdp planned_mdp(planned ? *planned : problem);
    const ParameterValues parameters = options->allocator.values();
    options->monte_carlo.check_allocator_memory(options->solver, problem, parameters);
    if (options->exact || allocator_registry().find(options->solver).capabilities.has(Capability::optimal)) {
      check_exact_work(problem, max_states_of(parameters), options->instance, flag_spelling());
    }
    const AllocatorFactory factory = make_allocator_factory(options->solver, planned_mdp, parameters);

    MonteCarloOptions monte_carlo = options->monte_carlo.options();
    monte_carlo.time_decisions = !options->no_timing;
    ProgressBar bar("evaluate " + options->solver);
    monte_carlo.progress = [&bar](std::uint64_t done, std::uint64_t total) { bar.update(done, total); };
    const MonteCarloResult result = run_monte_carlo(
        mdp, options->regret ? with_regret(mdp, factory, max_states_of(parameters)) : factory, monte_carlo);

    std::optional<ExactEvaluation> exact;
    if (options->exact) {
      const auto allocator = factory();
      exact = evaluate_exactly(mdp, *allocator, max_states_of(parameters));
    }
    report::Evaluation evaluation{.solver = options->solver,
                                  .parameters = parameters,
                                  .instance = options->instance,
                                  .problem = &problem,
                                  .belief = options->belief,
                                  .seed = options->monte_carlo.seed,
                                  .result = result,
                                  .exact = exact,
                                  .regret = options->regret ? regret_estimate(result.statistics) : std::nullopt,
                                  .timing = !options->no_timing};
    fmt::print("{}", options->json ? report::to_json(evaluation) + "\n" : report::to_text(evaluation));
  });
}

}  // namespace ontime::cli
