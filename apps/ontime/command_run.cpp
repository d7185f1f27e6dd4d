// `ontime run --domain NAME --solver NAME`: episodes in which an allocator drives the domain's
// real motion planner step by step (several refinements interleaved), against the success the
// allocator expects from the fitted instance. With `--effort wall` (or `--live`) every episode
// is a live session (session.hpp): the allocator's thinking and the planner's overruns are
// charged against the deadline in seconds, the planner's time being real (wall) or the nominal
// seconds of its collision checks (checks). The episodes are domains::run_planner_episodes
// (planner_run.hpp), the output the domains report's.

#include <fmt/format.h>

#include <filesystem>
#include <optional>
#include <vector>

#include "cluster_job.hpp"
#include "common.hpp"
#include "data_paths.hpp"
#include "memory_limits.hpp"
#include "number_options.hpp"
#include "ontime/domains/planner_run.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/domains/report.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "output_paths.hpp"
#include "timeline_plot.hpp"

namespace ontime::cli {

void add_run_command(CLI::App& app) {
  struct Options {
    std::string domain;
    std::string world;
    std::string instance;
    std::string belief;
    std::string act;  // empty: the instance's own mode
    std::string solver;
    std::string effort = "checks";
    std::uint64_t episodes = 200;
    std::uint64_t seed = 1;
    unsigned threads = 0;
    double checks_per_second = 0;
    bool exact = false;
    bool independent_starts = false;
    bool json = false;
    bool live = false;
    double decision_share = 0.5;
    std::string timeline;
    std::uint64_t timeline_episode = 0;
    bool no_plot = false;
    AllocatorFlags allocator;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("run", "Episodes in which an allocator drives a domain's real motion planner");
  command->add_option("--domain", options->domain, "Domain")->required();
  add_solver_option(*command, options->solver);
  command->add_option("--instance", options->instance,
                      "The allocator's model (default: data/instances/DOMAIN.json in the current directory, as collect "
                      "writes it, else the one installed with ontime)");
  command->add_option("--belief", options->belief,
                      "Decide with this instance's distributions, INSTANCE's skeletons and culprits kept (e.g. a "
                      "backtracking-ignorant fit of the same log)");
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
  add_act_option(*command, options->act,
                 "Concurrent: the robot executes each motion it starts while the planner refines the next from where "
                 "that motion ends (on the model's steps, or live on the robot's clock)");
  command->add_flag("--live", options->live,
                    "Live episodes on the clock (always with --effort wall): the allocator's thinking and the "
                    "planner's overruns are charged; with --effort checks planner calls count their nominal seconds");
  add_number_option(*command, "--decision-share", options->decision_share,
                    "Live: the share of a step an anytime allocator (mcts) thinks per decision", kPositive, 1e6);
  command->add_option("--timeline", options->timeline,
                      "Live: draw one episode's timeline into this PNG (its data beside it as .csv)");
  add_number_option(*command, "--timeline-episode", options->timeline_episode, "The episode --timeline draws");
  command->add_flag("--no-plot", options->no_plot, "With --timeline: write the .csv only");
  command->add_flag("--json", options->json, "Print JSON (live: every episode and its timeline)");
  options->allocator.add_to(*command);
  command->callback([options, command] {
    check_solver_names({options->solver});
    const bool live = options->live || options->effort == "wall";
    for (const char* name : {"--decision-share", "--timeline", "--timeline-episode", "--no-plot"}) {
      if (!live && command->count(name) > 0) {
        throw UsageError(fmt::format("{} needs live episodes (--live or --effort wall)", name));
      }
    }
    if (options->timeline_episode >= options->episodes) {
      throw UsageError(fmt::format("--timeline-episode {}: the run has episodes 0 to {}", options->timeline_episode,
                                   options->episodes - 1));
    }
    const std::filesystem::path world =
        options->world.empty() ? default_world_file(options->domain) : std::filesystem::path(options->world);
    const std::filesystem::path instance =
        options->instance.empty() ? default_model_file(options->domain) : std::filesystem::path(options->instance);
    std::filesystem::path timeline_png;
    std::filesystem::path timeline_data;
    if (!options->timeline.empty()) {
      timeline_png = options->timeline;
      timeline_data = timeline_png;
      timeline_data.replace_extension(".csv");
      std::vector<OutputFile> outputs{{"--timeline (plotted data)", timeline_data}};
      if (!options->no_plot) outputs.push_back({"--timeline", timeline_png});
      check_outputs(outputs, {world, instance});
    }
    const domains::LoadedDomain loaded = domains::load_domain(options->domain, world);
    Problem problem = load_problem(instance);
    if (!options->act.empty()) problem = problem.with_acting(*parse_acting(options->act));
    std::optional<Problem> belief;
    if (!options->belief.empty()) {
      belief.emplace(load_problem(options->belief));
      try {
        (void)with_distributions_of(problem, *belief);
      } catch (const UsageError& error) {
        throw UsageError(options->belief + ": " + error.what() + " (--belief against " + instance.string() + ")");
      }
    }
    domains::PlannerRunOptions run;
    run.belief = belief ? &*belief : nullptr;
    run.belief_source = options->belief;
    run.solver = options->solver;
    run.parameters = options->allocator.values();
    run.episodes = options->episodes;
    run.seed = options->seed;
    run.threads = options->threads;
    run.effort = domains::effort_settings(loaded.defaults, options->effort, options->checks_per_second);
    run.independent_starts = options->independent_starts;
    run.exact = options->exact;
    run.live = options->live;
    run.decision_share = options->decision_share;
    run.ranks = job_ranks();
    domains::check_planner_run_request(problem, instance.string(), run, flag_spelling());
    domains::check_domain_actions(*loaded.domain, problem, instance.string());
    const domains::PlannerRun result = domains::run_planner_episodes(*loaded.domain, problem, run);
    if (!timeline_data.empty() && is_job_root()) {  // rank 0 writes
      const EpisodeResult& shown = result.episodes[options->timeline_episode];
      write_file_atomically(timeline_data, domains::report::timeline_csv(problem, shown));
      if (!options->no_plot) {
        const std::string title =
            fmt::format("{} on {}, episode {}: {} at {:.1f} s of {:.1f} s", options->solver, options->domain,
                        options->timeline_episode, domains::report::status_name(shown.status), shown.live.elapsed,
                        problem.deadline() * problem.step_seconds());
        plot_timeline(problem, shown, timeline_data, timeline_png, title);
      }
    }
    domains::report::Run report{.domain = options->domain,
                                .instance = instance.string(),
                                .problem = &problem,
                                .options = &run,
                                .result = &result};
    if (!timeline_data.empty()) {
      report.timeline_episode = options->timeline_episode;
      report.timeline_files = timeline_data.string() + (options->no_plot ? "" : ", " + timeline_png.string());
    }
    fmt::print("{}", options->json ? domains::report::to_json(report) + "\n" : domains::report::to_text(report));
  });
}

}  // namespace ontime::cli
