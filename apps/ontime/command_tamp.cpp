// `ontime tamp --world W --library L --deadline S --solver NAME`: the whole deadline-aware TAMP loop
// on the clock. A task planner streams skeletons (room paths in order of length for a navigation
// world, else the domain's skeletons in order), each arriving in the episode's live session as it
// is found and charged its search time; the allocator decides which action the real motion planner
// (OMPL + FCL) refines next; the distributions it decides with come from a library of fitted
// actions (e.g. every doorway move, collected once). Episodes, their success rate and charges,
// and a picture of one episode: the map with the skeletons found coloured by the effort they got,
// and the timeline of its session.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include "cluster_job.hpp"
#include "common.hpp"
#include "data_paths.hpp"
#include "live_report.hpp"
#include "number_options.hpp"
#include "ontime/domains/navigation.hpp"
#include "ontime/domains/planner_world.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/domains/task_planner.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "output_paths.hpp"
#include "python_runner.hpp"

namespace ontime::cli {
namespace {

// The drawing of one episode for python/plot_tamp.py: the world, every skeleton found with the
// planning seconds its actions got (an action shared by a prefix counts for each skeleton that
// has it), and the motions found.
Json episode_drawing(const domains::Domain& domain, const domains::PlannerWorld& world, const Problem& problem,
                     const EpisodeResult& shown, const std::string& title) {
  const auto* navigation = dynamic_cast<const domains::NavigationDomain*>(&domain);
  std::vector<double> action_seconds(static_cast<std::size_t>(problem.action_count()), 0.0);
  for (const LiveStep& step : shown.timeline) {
    if (step.action >= 0) action_seconds[static_cast<std::size_t>(step.action)] += step.planning_seconds;
  }
  Json drawing;
  drawing["title"] = title;
  drawing["polygons"] = Json::array();
  for (const domains::ScenePolygon& polygon : domain.scene().polygons) {
    drawing["polygons"].push_back({{"kind", polygon.kind},
                                   {"label", polygon.label},
                                   {"view", polygon.view},
                                   {"points", points_json(polygon.points)}});
  }
  drawing["skeletons"] = Json::array();
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    std::vector<std::string> moves;
    double seconds = 0;
    for (const int action : problem.skeleton(k)) {
      moves.push_back(world.actions()[static_cast<std::size_t>(action)].action);
      seconds += action_seconds[static_cast<std::size_t>(action)];
    }
    Json skeleton = {{"index", k},
                     {"label", fmt::format("σ{}: {}", k + 1, domain.describe(moves))},
                     {"planning_seconds", seconds},
                     {"executed", shown.status == Status::success && shown.solution == k}};
    if (navigation != nullptr) skeleton["points"] = points_json(domains::room_path_points(navigation->world(), moves));
    drawing["skeletons"].push_back(std::move(skeleton));
  }
  drawing["motions"] = Json::array();
  std::set<int> plan;
  if (shown.status == Status::success) {
    for (const int action : problem.skeleton(shown.solution)) plan.insert(action);
  }
  for (int a = 0; a < problem.action_count(); ++a) {
    const domains::Refinement* refinement = world.refinement(a);
    if (refinement == nullptr || refinement->status() != domains::RefinementStatus::found) continue;
    drawing["motions"].push_back({{"action", problem.action(a).id},
                                  {"executed", plan.contains(a)},
                                  {"points", points_json(domain.trace(refinement->motion()))}});
  }
  return drawing;
}

}  // namespace

void add_tamp_command(CLI::App& app) {
  struct Options {
    std::string domain = "navigation";
    std::string world;
    std::string library;
    std::string solver;
    double deadline = 0;
    std::string effort = "checks";
    std::uint64_t episodes = 100;
    std::uint64_t seed = 1;
    unsigned threads = 0;
    double task_seconds = 0.5;
    int period = 2;
    int max_skeletons = 16;
    double decision_share = 0.5;
    std::string clock = "real";
    ThinkingModel thinking;
    std::string picture;
    std::uint64_t picture_episode = 0;
    bool no_plot = false;
    bool json = false;
    AllocatorFlags allocator;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "tamp", "The whole TAMP loop on the clock: skeletons streamed by a task planner, refined by the real planner");
  command->add_option("--domain", options->domain, "Domain")->capture_default_str();
  command->add_option("--world", options->world, "World file (default: data/domains/DOMAIN.json)");
  command
      ->add_option("--library", options->library,
                   "Instance whose actions give the distributions of every action the task planner may produce "
                   "(e.g. fitted from `collect --every-move`)")
      ->required();
  add_number_option(*command, "--deadline", options->deadline,
                    "Deadline in seconds (whole steps of the library's step_seconds count)", 1e-9)
      ->required();
  add_solver_option(*command, options->solver);
  command->add_option("--effort", options->effort, "Effort unit: checks (deterministic) or wall")
      ->capture_default_str();
  add_number_option(*command, "--episodes", options->episodes, "Episodes", std::uint64_t{1});
  add_number_option(*command, "--seed", options->seed, "Seed of the episodes (episode i uses stream i of it)");
  add_threads_option(*command, options->threads, "Worker threads (0: one per hardware thread)");
  add_number_option(*command, "--task-seconds", options->task_seconds,
                    "Search seconds charged to the deadline for each skeleton the task planner finds", 0.0, 1e6);
  add_number_option(*command, "--arrival-period", options->period,
                    "Steps between two skeletons of the task planner (sooner when none found can still succeed)", 1,
                    10'000);
  add_number_option(*command, "--max-skeletons", options->max_skeletons, "Skeletons the task planner finds at most", 1,
                    Problem::kMaxSkeletons);
  add_number_option(*command, "--decision-share", options->decision_share,
                    "Share of a slice an anytime allocator thinks per decision (without its own budget)", 1e-9, 1e6);
  command
      ->add_option("--clock", options->clock,
                   "real: the allocator's thinking and the task planner's search take the real time they take (a "
                   "robot's view); model: thinking is charged by --decision-seconds and --iteration-seconds, and "
                   "nothing real is on the clock, so the same seed gives the same episodes on any machine (reports)")
      ->check(CLI::IsMember({"real", "model"}))
      ->capture_default_str();
  add_number_option(*command, "--decision-seconds", options->thinking.seconds_per_decision,
                    "--clock model: seconds charged per decision", 0.0, 1e6);
  add_number_option(*command, "--iteration-seconds", options->thinking.seconds_per_iteration,
                    "--clock model: seconds charged per search iteration of an anytime allocator", 1e-12, 1e6);
  command->add_option("--picture", options->picture,
                      "Draw one episode: the map into this PNG (data beside it as .json) and the timeline into "
                      "NAME-timeline.png (data as .csv)");
  add_number_option(*command, "--picture-episode", options->picture_episode, "The episode --picture draws");
  command->add_flag("--no-plot", options->no_plot, "With --picture: write the data only");
  command->add_flag("--json", options->json, "Print JSON (with every episode and its timeline)");
  options->allocator.add_to(*command);
  command->callback([options, command] {
    if (options->picture.empty() && (command->count("--picture-episode") > 0 || options->no_plot)) {
      throw UsageError("--picture-episode and --no-plot need --picture");
    }
    if (options->clock == "real" &&
        (command->count("--decision-seconds") > 0 || command->count("--iteration-seconds") > 0)) {
      throw UsageError("--decision-seconds and --iteration-seconds need --clock model");
    }
    if (options->clock == "model" && options->effort != "checks") {
      throw UsageError("--clock model needs --effort checks (wall-clock effort is real time)");
    }
    if (options->picture_episode >= options->episodes) {
      throw UsageError(fmt::format("--picture-episode {}: the run has episodes 0 to {}", options->picture_episode,
                                   options->episodes - 1));
    }
    const std::filesystem::path world_file =
        options->world.empty() ? default_world_file(options->domain) : std::filesystem::path(options->world);
    const domains::LoadedDomain loaded = domains::load_domain(options->domain, world_file);
    const domains::Domain& domain = *loaded.domain;
    const Problem library = load_problem(options->library);
    const double steps = std::floor(options->deadline / library.step_seconds() + 1e-9);
    if (steps < 1 || steps > static_cast<double>(Problem::kMaxDeadline)) {
      throw UsageError(fmt::format("--deadline {}: {} steps of {} s; a deadline takes 1 to {} steps", options->deadline,
                                   steps, library.step_seconds(), Problem::kMaxDeadline));
    }
    std::filesystem::path map_png, map_data, timeline_png, timeline_data;
    if (!options->picture.empty()) {
      map_png = options->picture;
      map_data = std::filesystem::path(map_png).replace_extension(".json");
      timeline_png = map_png.parent_path() / (map_png.stem().string() + "-timeline.png");
      timeline_data = std::filesystem::path(timeline_png).replace_extension(".csv");
      std::vector<OutputFile> outputs{{"--picture (map data)", map_data}, {"--picture (timeline data)", timeline_data}};
      if (!options->no_plot) {
        outputs.push_back({"--picture", map_png});
        outputs.push_back({"--picture (timeline)", timeline_png});
      }
      check_outputs(outputs, {world_file, options->library});
    }

    const ParameterValues parameters = options->allocator.values();
    // Every action the task planner may produce must be in the library: its skeletons are checked
    // as they come (the streaming world throws for one that is not), and here up front for a
    // domain with fixed skeletons.
    const auto* navigation = dynamic_cast<const domains::NavigationDomain*>(&domain);
    const domains::TaskPlannerFactory planners =
        navigation != nullptr ? domains::room_path_planners(navigation->world(), options->max_skeletons)
                              : domains::fixed_skeleton_planners(domain);
    {
      const auto planner = planners();
      for (int k = 0; k < options->max_skeletons; ++k) {
        const auto skeleton = planner->next();
        if (!skeleton) break;
        for (const std::string& action : *skeleton) {
          if (library.find_action(action) < 0) {
            throw InputError(options->library, "actions",
                             fmt::format("no action '{}', which the task planner's skeleton {} needs", action, k + 1));
          }
        }
      }
    }
    StreamingRun streaming;
    streaming.name = fmt::format("{} ({})", domain.name(), world_file.filename().string());
    streaming.deadline = static_cast<Steps>(steps);
    streaming.step_seconds = library.step_seconds();
    streaming.period = options->period;
    streaming.max_skeletons = options->max_skeletons;
    const std::string solver = options->solver;
    streaming.make_allocator = [solver, parameters](const Mdp& mdp) {
      return make_allocator_factory(solver, mdp, parameters)();
    };
    domains::StreamingWorldOptions stream;
    stream.library = &library;
    stream.task_planners = planners;
    stream.seconds_per_skeleton = options->task_seconds;
    domains::PlannerWorldOptions planner;
    planner.effort.unit = domains::parse_effort_unit(options->effort);
    planner.effort.checks_per_second = loaded.defaults.collection.checks_per_second;
    if (options->clock == "model") planner.thinking = options->thinking;

    MonteCarloOptions episodes;
    // An anytime allocator given its own budget (--iterations, --time-budget) thinks that much per
    // decision, charged all the same; otherwise the session gives it decision_share of a slice.
    const AllocatorKind& kind = allocator_registry().find(solver);
    const ParameterReader reader(kind, parameters);
    if (kind.capabilities.has(Capability::anytime) && (reader.given("iterations") || reader.given("time-budget"))) {
      const double seconds = reader.given("time-budget") ? reader.real("time-budget") : 0.0;
      if (!reader.given("iterations")) {
        if (seconds > 0) episodes.decision_budget = DecisionBudget::seconds(seconds);
      } else if (seconds > 0) {
        episodes.decision_budget = DecisionBudget::either(reader.integer("iterations"), seconds);
      } else {
        episodes.decision_budget = DecisionBudget::iterations(reader.integer("iterations"));
      }
    }
    episodes.episodes = options->episodes;
    episodes.seed = options->seed;
    episodes.threads = options->threads;
    episodes.ranks = job_ranks();
    episodes.live = LiveRun{LiveOptions{.decision_share = options->decision_share}, options->json};
    std::vector<EpisodeResult> results(options->episodes);
    std::vector<int> skeletons_found(options->episodes, 0);
    // Each episode writes its own slot: no two threads touch one.
    episodes.on_episode = [&](std::uint64_t episode, const EpisodeResult& result) {
      skeletons_found[episode] = result.skeletons;
      if (options->json) results[episode] = result;
    };
    ProgressBar progress("tamp");
    episodes.progress = [&progress](std::uint64_t done, std::uint64_t total) { progress.update(done, total); };
    const MonteCarloResult summary =
        run_streaming_episodes(streaming, domains::streaming_planner_worlds(domain, stream, planner), episodes);
    double mean_skeletons = 0;
    for (const int found : skeletons_found) mean_skeletons += found;
    mean_skeletons /= static_cast<double>(options->episodes);
    const double refinements_started =
        summary.world_statistics.find("refinements_started").value_or(0.0) / static_cast<double>(summary.episodes);
    const double deadline_seconds = streaming.deadline * streaming.step_seconds;

    // The picture: the episode run again on its own, so that its world still holds its motions.
    if (!map_data.empty() && is_job_root()) {  // rank 0 draws and writes
      domains::PlannerWorld world(domain, stream, planner);
      LiveRun live = *episodes.live;
      live.keep_timeline = true;
      const EpisodeResult shown =
          run_streaming_episode(streaming, world, stream_seed(options->seed, options->picture_episode),
                                episodes.decision_budget, nullptr, live);
      if (shown.problem != nullptr) {
        const std::string title =
            fmt::format("{} on {}, episode {}: {} at {:.1f} s of {:.1f} s, {} skeletons", options->solver,
                        world_file.filename().string(), options->picture_episode, status_name(shown.status),
                        shown.live.elapsed, deadline_seconds, shown.skeletons);
        write_file_atomically(map_data, episode_drawing(domain, world, *shown.problem, shown, title).dump(1) + "\n");
        write_file_atomically(timeline_data, timeline_csv(*shown.problem, shown));
        if (!options->no_plot) {
          run_python_script("plot_tamp.py", map_png, [&](const std::string& figure) {
            return std::vector<std::string>{"--data", map_data.string(), "--output", figure};
          });
          plot_timeline(*shown.problem, shown, timeline_data, timeline_png, title);
        }
      }
    }

    if (options->json) {
      Json out;
      out["domain"] = options->domain;
      out["world"] = world_file.string();
      out["library"] = options->library;
      out["solver"] = options->solver;
      out["parameters"] = parameters_json(allocator_registry().find(options->solver), parameters);
      out["deadline_seconds"] = deadline_seconds;
      out["deadline_steps"] = streaming.deadline;
      out["step_seconds"] = streaming.step_seconds;
      out["task_seconds"] = options->task_seconds;
      out["arrival_period"] = options->period;
      out["max_skeletons"] = options->max_skeletons;
      out["effort"] = options->effort;
      out["decision_share"] = options->decision_share;
      out["clock"] = options->clock;
      if (options->clock == "model") {
        out["decision_seconds"] = options->thinking.seconds_per_decision;
        out["iteration_seconds"] = options->thinking.seconds_per_iteration;
      }
      out["episodes"] = summary.episodes;
      out["seed"] = options->seed;
      out["successes"] = summary.successes;
      out["success_rate"] = summary.success_rate;
      out["ci95"] = summary.ci95;
      out["mean_skeletons_found"] = mean_skeletons;
      out["refinements_started"] = refinements_started;
      out["seconds"] = summary.seconds;
      add_charges(out, summary.live_mean, "mean_");
      Json detail = Json::array();
      for (const auto& result : results) {
        Json episode = live_json(result);
        episode["skeletons_found"] = result.skeletons;
        detail.push_back(std::move(episode));
      }
      out["episode_results"] = std::move(detail);
      print_json(out);
      return;
    }
    fmt::print("solver               {} on {} ({} s deadline = {} steps of {} s)\n", options->solver,
               world_file.string(), deadline_seconds, streaming.deadline, streaming.step_seconds);
    fmt::print("success              {:.4f} ± {:.4f}  ({} of {} episodes, seed {}, {:.1f} s)\n", summary.success_rate,
               summary.ci95, summary.successes, summary.episodes, options->seed, summary.seconds);
    fmt::print("skeletons found      {:.2f} per episode (at most {}, {} s of search each, one every {} steps)\n",
               mean_skeletons, options->max_skeletons, options->task_seconds, options->period);
    fmt::print(
        "charged per episode  thinking {:.3f} s, planning {:.3f} s (overruns {:.3f} s), search and outside {:.3f} s: "
        "{:.3f} s of {:.1f} s\n",
        summary.live_mean.decision, summary.live_mean.planning, summary.live_mean.overrun, summary.live_mean.outside,
        summary.live_mean.elapsed, deadline_seconds);
    fmt::print("refinements started  {:.2f} per episode\n", refinements_started);
    if (options->clock == "model") {
      fmt::print("clock                model: {} s per decision, {} s per search iteration; nothing real\n",
                 options->thinking.seconds_per_decision, options->thinking.seconds_per_iteration);
    } else {
      fmt::print("clock                real (thinking and search as measured; --clock model to reproduce)\n");
    }
    if (!map_data.empty()) {
      fmt::print("picture              episode {}: {}, {}{}\n", options->picture_episode, map_data.string(),
                 timeline_data.string(),
                 options->no_plot ? "" : ", " + map_png.string() + ", " + timeline_png.string());
    }
  });
}

}  // namespace ontime::cli
