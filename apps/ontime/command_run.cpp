// `ontime run --domain NAME --solver NAME`: episodes in which an allocator drives the domain's
// real motion planner step by step (several refinements interleaved), against the success the
// allocator expects from the fitted instance.

#include <fmt/format.h>

#include <filesystem>

#include "common.hpp"
#include "data_paths.hpp"
#include "memory_limits.hpp"
#include "number_options.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/domains/planner_world.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/episode_runner.hpp"
#include "ontime/instance_io.hpp"

namespace ontime::cli {

void add_run_command(CLI::App& app) {
  struct Options {
    std::string domain;
    std::string world;
    std::string instance;
    std::string solver;
    std::string effort = "checks";
    std::uint64_t episodes = 200;
    std::uint64_t seed = 1;
    unsigned threads = 0;
    double checks_per_second = 0;
    bool exact = false;
    bool independent_starts = false;
    bool json = false;
    AllocatorFlags allocator;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("run", "Episodes in which an allocator drives a domain's real motion planner");
  command->add_option("--domain", options->domain, "Domain")->required();
  add_solver_option(*command, options->solver);
  command->add_option("--instance", options->instance,
                      "The allocator's model (default: data/instances/DOMAIN.json in the current directory, as collect "
                      "writes it, else the one installed with ontime)");
  command->add_option("--world", options->world, "World file (default: data/domains/DOMAIN.json)");
  add_number_option(*command, "--episodes", options->episodes, "Episodes", std::uint64_t{1});
  add_number_option(*command, "--seed", options->seed, "Seed (episode e uses stream e)");
  add_threads_option(*command, options->threads,
                     "Worker threads (0: one per hardware thread); results do not depend on it");
  command->add_option("--effort", options->effort, "Effort unit: checks (deterministic) or wall")
      ->check(CLI::IsMember({"checks", "wall"}))
      ->capture_default_str();
  add_number_option(*command, "--checks-per-second", options->checks_per_second,
                    "Nominal collision checks per second of the checks unit (default: the world file's)", kPositive,
                    std::numeric_limits<double>::max(), false);
  command->add_flag(
      "--independent-starts", options->independent_starts,
      "Start every action after the first from a fresh pose in its room, not where the previous refinement ended");
  command->add_flag("--exact", options->exact, "Also the exact success the allocator expects from the instance");
  command->add_flag("--json", options->json, "Print JSON");
  options->allocator.add_to(*command);
  command->callback([options] {
    check_solver_names({options->solver});
    const std::filesystem::path world =
        options->world.empty() ? default_world_file(options->domain) : std::filesystem::path(options->world);
    const std::filesystem::path instance =
        options->instance.empty() ? default_model_file(options->domain) : std::filesystem::path(options->instance);
    const domains::LoadedDomain loaded = domains::load_domain(options->domain, world);
    const Problem problem = load_problem(instance);
    const Mdp mdp(problem);
    const ParameterValues parameters = options->allocator.values();
    check_tree_memory(options->solver, parameters, options->episodes, options->threads);
    if (options->exact || allocator_registry().find(options->solver).capabilities.has(Capability::optimal)) {
      check_state_cap_memory(problem, max_states_of(parameters));
    }
    const AllocatorFactory factory = make_allocator_factory(options->solver, mdp, parameters);
    domains::PlannerWorldOptions planner;
    planner.effort.unit = domains::parse_effort_unit(options->effort);
    planner.effort.checks_per_second =
        options->checks_per_second > 0 ? options->checks_per_second : loaded.defaults.collection.checks_per_second;
    planner.independent_starts = options->independent_starts;
    MonteCarloOptions episodes;
    episodes.episodes = options->episodes;
    episodes.seed = options->seed;
    episodes.threads = options->threads;
    const MonteCarloResult summary =
        run_episodes(mdp, domains::planner_worlds(*loaded.domain, problem, planner), factory, episodes);
    const double refinements_started =
        summary.world_statistics.find("refinements_started").value_or(0.0) / static_cast<double>(summary.episodes);
    std::optional<ExactEvaluation> exact;
    if (options->exact) {
      const auto allocator = factory();
      exact = evaluate_exactly(mdp, *allocator, max_states_of(parameters));
    }
    if (options->json) {
      Json out;
      out["domain"] = options->domain;
      out["instance"] = instance.string();
      out["solver"] = options->solver;
      out["parameters"] = parameters_json(allocator_registry().find(options->solver), parameters);
      out["episodes"] = summary.episodes;
      out["seed"] = options->seed;
      out["successes"] = summary.successes;
      out["success_rate"] = summary.success_rate;
      out["ci95"] = summary.ci95;
      out["independent_starts"] = options->independent_starts;
      out["refinements_started"] = refinements_started;
      out["seconds"] = summary.seconds;
      if (exact) out["model_exact_success_probability"] = exact->success_probability;
      print_json(out);
      return;
    }
    fmt::print("solver               {} on the {} domain (model {})\n", options->solver, options->domain,
               instance.string());
    fmt::print("real planner         {:.4f} ± {:.4f}  ({} of {} episodes, seed {}, {:.1f} s)\n", summary.success_rate,
               summary.ci95, summary.successes, summary.episodes, options->seed, summary.seconds);
    fmt::print("refinements started  {:.2f} per episode\n", refinements_started);
    if (exact) fmt::print("model, exact         {:.4f}\n", exact->success_probability);
  });
}

}  // namespace ontime::cli
