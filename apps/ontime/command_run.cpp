// `ontime run --domain NAME --solver NAME`: episodes in which an allocator drives the domain's
// real motion planner step by step (several refinements interleaved), against the success the
// allocator expects from the fitted instance. With `--effort wall` (or `--live`) every episode
// is a live session (session.hpp): the allocator's thinking and the planner's overruns are
// charged against the deadline in seconds, the planner's time being real (wall) or the nominal
// seconds of its collision checks (checks).

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <span>
#include <vector>

#include "cluster_job.hpp"
#include "common.hpp"
#include "data_paths.hpp"
#include "live_report.hpp"
#include "memory_limits.hpp"
#include "number_options.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/domains/planner_world.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "output_paths.hpp"
#include "python_runner.hpp"

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
    const Problem problem = load_problem(instance);
    const Mdp mdp(problem);
    const ParameterValues parameters = options->allocator.values();
    check_allocator_memory(options->solver, problem, parameters, options->episodes, options->threads);
    if (options->exact || allocator_registry().find(options->solver).capabilities.has(Capability::optimal)) {
      check_exact_work(problem, max_states_of(parameters), instance.string(), flag_spelling());
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
    episodes.ranks = job_ranks();
    std::vector<EpisodeResult> results;
    if (live) {
      episodes.live = LiveRun{LiveOptions{.decision_share = options->decision_share}, true};
      results.resize(options->episodes);
      // Each episode writes its own slot: no two threads touch one.
      episodes.on_episode = [&results](std::uint64_t episode, const EpisodeResult& result) {
        results[episode] = result;
      };
    }
    const MonteCarloResult summary =
        run_episodes(mdp, domains::planner_worlds(*loaded.domain, problem, planner), factory, episodes);
    const double refinements_started =
        summary.world_statistics.find("refinements_started").value_or(0.0) / static_cast<double>(summary.episodes);
    std::optional<ExactEvaluation> exact;
    if (options->exact) {
      const auto allocator = factory();
      exact = evaluate_exactly(mdp, *allocator, max_states_of(parameters));
    }
    if (!timeline_data.empty() && is_job_root()) {  // rank 0 writes
      const EpisodeResult& shown = results[options->timeline_episode];
      write_file_atomically(timeline_data, timeline_csv(problem, shown));
      if (!options->no_plot) {
        const std::string title = fmt::format("{} on {}, episode {}: {} at {:.1f} s of {:.1f} s", options->solver,
                                              options->domain, options->timeline_episode, status_name(shown.status),
                                              shown.live.elapsed, problem.deadline() * problem.step_seconds());
        plot_timeline(problem, shown, timeline_data, timeline_png, title);
      }
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
      out["effort"] = options->effort;
      out["live"] = live;
      if (live) {
        out["decision_share"] = options->decision_share;
        out["step_clock_successes"] = summary.model_successes;
        out["step_clock_undecided"] = summary.model_undecided;
        add_charges(out, summary.live_mean, "mean_");
        Json detail = Json::array();
        for (const EpisodeResult& result : results) detail.push_back(live_json(result));
        out["episode_results"] = std::move(detail);
      }
      print_json(out);
      return;
    }
    fmt::print("solver               {} on the {} domain (model {})\n", options->solver, options->domain,
               instance.string());
    fmt::print("real planner         {:.4f} ± {:.4f}  ({} of {} episodes, seed {}, {:.1f} s){}\n", summary.success_rate,
               summary.ci95, summary.successes, summary.episodes, options->seed, summary.seconds, live ? ", live" : "");
    if (live) {
      fmt::print(
          "same calls, steps    {:.4f}  ({} of {} by the model's step clock; {} undecided when the live episode "
          "ended)\n",
          static_cast<double>(summary.model_successes) / static_cast<double>(summary.episodes), summary.model_successes,
          summary.episodes, summary.model_undecided);
      fmt::print(
          "charged per episode  thinking {:.3f} s, planning {:.3f} s (overruns {:.3f} s): {:.3f} s of {:.1f} s\n",
          summary.live_mean.decision, summary.live_mean.planning, summary.live_mean.overrun, summary.live_mean.elapsed,
          problem.deadline() * problem.step_seconds());
    }
    if (!timeline_data.empty()) {
      fmt::print("timeline             episode {}: {}{}\n", options->timeline_episode, timeline_data.string(),
                 options->no_plot ? "" : ", " + timeline_png.string());
    }
    fmt::print("refinements started  {:.2f} per episode\n", refinements_started);
    if (exact) fmt::print("model, exact         {:.4f}\n", exact->success_probability);
  });
}

}  // namespace ontime::cli
