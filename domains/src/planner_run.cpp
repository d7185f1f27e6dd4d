#include "ontime/domains/planner_run.hpp"

#include <optional>
#include <stdexcept>

#include "episode_options.hpp"
#include "ontime/allocators/belief_models.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/domains/planner_world.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/util/parallel.hpp"

namespace ontime::domains {

bool is_live(const PlannerRunOptions& options) noexcept {
  return options.live || options.effort.unit == EffortUnit::wall_clock;
}

void check_planner_run_request(const Problem& problem, const std::string& source, const PlannerRunOptions& options,
                               const ParameterSpelling& spelling) {
  allocator_registry().check_memory(options.solver, problem, options.parameters,
                                    worker_count(options.episodes, options.threads), spelling);
  if (options.exact || allocator_registry().find(options.solver).capabilities.has(Capability::optimal)) {
    check_exact_work(problem, max_states_of(options.parameters), source, spelling);
  }
}

void check_domain_actions(const Domain& domain, const Problem& problem, const std::string& source) {
  if (domain.feature_names().empty()) return;
  for (const Action& action : problem.actions()) {
    try {
      (void)domain.action_features(action.id);
    } catch (const std::invalid_argument& error) {
      throw InputError(source, "actions." + action.id,
                       "not an action of the world '" + domain.name() + "' (" + error.what() + ")");
    }
  }
}

namespace {

// Live episodes: each one's result kept in run.episodes (with its timeline), for the report.
void keep_live_episodes(const PlannerRunOptions& options, MonteCarloOptions& episodes, PlannerRun& run) {
  episodes.live = LiveRun{LiveOptions{.decision_share = options.decision_share}, true};
  run.episodes.resize(options.episodes);
  // Each episode writes its own slot: no two threads touch one.
  episodes.on_episode = [&run](std::uint64_t episode, const EpisodeResult& result) { run.episodes[episode] = result; };
}

// Acting while planning (SPEC §10): the robot starts each refined motion while the planner refines
// the next from where that motion ends (the planner world's starts, unless independent), on the
// model's step clock, or live on the robot's clock (live ConcurrentSessions). With a belief the
// allocator decides on the belief's model (ConcurrentBeliefModels).
PlannerRun run_concurrent_planner_episodes(const Domain& domain, const Problem& problem,
                                           const PlannerRunOptions& options) {
  std::optional<Problem> planned;
  if (options.belief != nullptr) planned.emplace(with_distributions_of(problem, *options.belief));
  const ConcurrentBeliefModels models(problem, planned ? &*planned : nullptr);
  const ConcurrentMdp& mdp = models.world();
  const ConcurrentAllocatorFactory factory = models.factory(options.solver, options.parameters);
  PlannerWorldOptions planner;
  planner.effort = options.effort;
  planner.independent_starts = options.independent_starts;
  MonteCarloOptions episodes = detail::monte_carlo_options(options);
  PlannerRun run;
  if (is_live(options)) keep_live_episodes(options, episodes, run);
  run.summary = run_concurrent_episodes(mdp, planner_worlds(domain, problem, planner), factory, episodes);
  run.refinements_started = run.summary.world_statistics.find("refinements_started").value_or(0.0) /
                            static_cast<double>(run.summary.episodes);
  if (options.exact) {
    const auto allocator = factory();
    run.exact = evaluate_exactly(mdp, *allocator, max_states_of(options.parameters), options.stop);
  }
  return run;
}

}  // namespace

PlannerRun run_planner_episodes(const Domain& domain, const Problem& problem, const PlannerRunOptions& options) {
  if (problem.acting() == Acting::concurrent) return run_concurrent_planner_episodes(domain, problem, options);
  const Mdp mdp(problem);
  const std::optional<Problem> planned = options.belief == nullptr
                                             ? std::nullopt
                                             : std::optional<Problem>(with_distributions_of(problem, *options.belief));
  const Mdp planned_mdp(planned ? *planned : problem);
  const AllocatorFactory factory = make_allocator_factory(options.solver, planned_mdp, options.parameters);
  PlannerWorldOptions planner;
  planner.effort = options.effort;
  planner.independent_starts = options.independent_starts;
  MonteCarloOptions episodes = detail::monte_carlo_options(options);
  PlannerRun run;
  if (is_live(options)) keep_live_episodes(options, episodes, run);
  run.summary = run_episodes(mdp, planner_worlds(domain, problem, planner), factory, episodes);
  run.refinements_started = run.summary.world_statistics.find("refinements_started").value_or(0.0) /
                            static_cast<double>(run.summary.episodes);
  run.backtracks =
      run.summary.world_statistics.find("backtracks").value_or(0.0) / static_cast<double>(run.summary.episodes);
  if (options.exact) {
    const auto allocator = factory();
    run.exact = evaluate_exactly(mdp, *allocator, max_states_of(options.parameters), options.stop);
  }
  return run;
}

}  // namespace ontime::domains
