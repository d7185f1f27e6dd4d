#include "ontime/domains/report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <span>

#include "ontime/report/report.hpp"

namespace ontime::domains::report {
namespace {

using Json = nlohmann::ordered_json;

std::string dump(const Json& value) { return value.dump(2); }

Json points_json(const Polyline& points) {
  Json list = Json::array();
  for (const auto& point : points) list.push_back({point[0], point[1]});
  return list;
}

Json polygons_json(const std::vector<ScenePolygon>& polygons) {
  Json list = Json::array();
  for (const ScenePolygon& polygon : polygons) {
    list.push_back({{"kind", polygon.kind},
                    {"label", polygon.label},
                    {"view", polygon.view},
                    {"points", points_json(polygon.points)}});
  }
  return list;
}

Json parameters_object(const std::string& solver, const ParameterValues& values) {
  return Json::parse(ontime::report::parameters_json(allocator_registry().find(solver), values));
}

// The charges of a live episode (prefix "") or their means over a run ("mean_").
void add_charges(Json& out, const LiveTotals& totals, const std::string& prefix) {
  out[prefix + "elapsed_seconds"] = totals.elapsed;
  out[prefix + "decision_seconds"] = totals.decision;
  out[prefix + "planning_seconds"] = totals.planning;
  out[prefix + "overrun_seconds"] = totals.overrun;
  out[prefix + "outside_seconds"] = totals.outside;
}

// A live episode: its status, charges and timeline.
Json live_episode(const EpisodeResult& result) {
  Json episode;
  episode["status"] = status_name(result.status);
  episode["step_clock_status"] = status_name(result.model_status);
  episode["solution"] = result.solution;
  episode["decisions"] = result.decisions;
  episode["steps"] = result.steps_used;
  add_charges(episode, result.live, "");
  Json timeline = Json::array();
  for (const LiveStep& step : result.timeline) {
    timeline.push_back({{"skeleton", step.skeleton},
                        {"action", step.action},
                        {"start", step.start},
                        {"outside_seconds", step.outside_seconds},
                        {"decision_seconds", step.decision_seconds},
                        {"planning_seconds", step.planning_seconds},
                        {"overrun_seconds", step.overrun_seconds},
                        {"observe_seconds", step.observe_seconds},
                        {"steps_charged", step.steps_charged},
                        {"refined", step.refined},
                        {"execution_seconds", step.refined ? Json(step.execution_seconds) : Json(nullptr)}});
    // A start of the robot acting while planning (SPEC §10): the action it began.
    if (step.started >= 0) timeline.back()["started"] = step.started;
  }
  episode["timeline"] = std::move(timeline);
  Json executions = Json::array();
  for (const LiveExecution& execution : result.executions) {
    executions.push_back({{"action", execution.action}, {"start", execution.start}, {"end", execution.end}});
  }
  episode["executions"] = std::move(executions);
  return episode;
}

// Every episode of a live run; streaming episodes with the skeletons their task planner found.
Json live_episodes(const std::vector<EpisodeResult>& episodes, bool skeletons_found) {
  Json list = Json::array();
  for (const EpisodeResult& episode : episodes) {
    Json entry = live_episode(episode);
    if (skeletons_found) entry["skeletons_found"] = episode.skeletons;
    list.push_back(std::move(entry));
  }
  return list;
}

Json episode_drawing_object(const EpisodeDrawing& drawing) {
  Json out;
  out["title"] = drawing.title;
  out["polygons"] = polygons_json(drawing.polygons);
  out["skeletons"] = Json::array();
  for (const EpisodeSkeleton& skeleton : drawing.skeletons) {
    Json entry = {{"index", skeleton.index},
                  {"label", skeleton.label},
                  {"planning_seconds", skeleton.planning_seconds},
                  {"executed", skeleton.executed}};
    if (!skeleton.points.empty()) entry["points"] = points_json(skeleton.points);
    out["skeletons"].push_back(std::move(entry));
  }
  out["motions"] = Json::array();
  for (const EpisodeMotion& motion : drawing.motions) {
    out["motions"].push_back(
        {{"action", motion.action}, {"executed", motion.executed}, {"points", points_json(motion.points)}});
  }
  return out;
}

double deadline_seconds(const TampResult& result) {
  return static_cast<double>(result.deadline_steps) * result.step_seconds;
}

}  // namespace

const char* status_name(Status status) noexcept {
  return status == Status::success ? "success" : status == Status::failure ? "failure" : "undecided";
}

std::string timeline_csv(const Problem& problem, const EpisodeResult& result) {
  // The first ten columns are those of plan-first timelines before the execution lane; the lane and
  // the execution's start and end come after them, so that readers of the ten keep working.
  std::string csv =
      "skeleton,action,start,outside_seconds,decision_seconds,planning_seconds,overrun_seconds,observe_seconds,"
      "refined,execution_seconds,lane,execution_start,execution_end\n";
  const auto execution_of = [&result](int action) -> const LiveExecution* {
    for (const LiveExecution& execution : result.executions) {
      if (execution.action == action) return &execution;
    }
    return nullptr;
  };
  for (const LiveStep& step : result.timeline) {
    const int named = step.started >= 0 ? step.started : step.action;
    const std::string action = named >= 0 ? problem.action(named).id : "";
    csv += fmt::format("{},{},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{},{:.9f}", step.skeleton,
                       ontime::report::csv_field(action), step.start, step.outside_seconds, step.decision_seconds,
                       step.planning_seconds, step.overrun_seconds, step.observe_seconds, step.refined ? 1 : 0,
                       step.refined ? step.execution_seconds : 0.0);
    const LiveExecution* started = step.started >= 0 ? execution_of(step.started) : nullptr;
    csv += started != nullptr ? fmt::format(",start,{:.9f},{:.9f}\n", started->start, started->end) : ",planning,,\n";
  }
  // The robot's lane: each execution from its start to its end.
  for (const LiveExecution& execution : result.executions) {
    csv += fmt::format("-1,{},{:.9f},0,0,0,0,0,0,{:.9f},execution,{:.9f},{:.9f}\n",
                       ontime::report::csv_field(problem.action(execution.action).id), execution.start,
                       execution.end - execution.start, execution.start, execution.end);
  }
  return csv;
}

double executed_plan_seconds(const Problem& problem, const EpisodeResult& result) {
  double execution = 0;
  if (result.status == Status::success) {
    const std::span<const int> plan = problem.skeleton(result.solution);
    for (const LiveStep& step : result.timeline) {
      if (step.refined && std::find(plan.begin(), plan.end(), step.action) != plan.end()) {
        execution += step.execution_seconds;
      }
    }
  }
  return execution;
}

std::string to_json(const MapDrawing& drawing) {
  Json out;
  out["title"] = drawing.title;
  out["polygons"] = polygons_json(drawing.polygons);
  out["paths"] = Json::array();
  for (const MapPath& path : drawing.paths) {
    out["paths"].push_back(
        {{"label", path.label}, {"points", points_json(path.points)}, {"end", points_json(path.end)}});
  }
  return out.dump(1);
}

std::string to_json(const EpisodeDrawing& drawing) { return episode_drawing_object(drawing).dump(1); }

std::string to_json(const GeneratedWorld& world) {
  Json out;
  out["output"] = world.output;
  out["name"] = world.name;
  out["rooms"] = world.rooms;
  out["doors"] = world.doors;
  out["furniture"] = world.furniture;
  out["start_room"] = world.start_room;
  out["goal_room"] = world.goal_room;
  return dump(out);
}

std::string to_text(const GeneratedWorld& world) {
  return fmt::format("Wrote {}: {} rooms, {} doors, {} pieces of furniture; start in {}, goal {}.\n", world.output,
                     world.rooms, world.doors, world.furniture, world.start_room, world.goal_room);
}

std::string to_json(const GeneratedKitchen& kitchen) {
  Json out;
  out["output"] = kitchen.output;
  out["name"] = kitchen.name;
  out["tables"] = kitchen.tables;
  out["regions"] = kitchen.regions;
  out["objects"] = kitchen.objects;
  out["skeletons"] = kitchen.skeletons;
  out["actions"] = kitchen.actions;
  Json goal = Json::object();
  for (const auto& [object, region] : kitchen.goal) goal[object] = region;
  out["goal"] = goal;
  return dump(out);
}

std::string to_text(const GeneratedKitchen& kitchen) {
  std::string goal;
  for (const auto& [object, region] : kitchen.goal) goal += (goal.empty() ? "" : ", ") + object + " to " + region;
  return fmt::format("Wrote {}: {} tables, {} regions, {} objects; goal {}; {} skeletons of {} actions.\n",
                     kitchen.output, kitchen.tables, kitchen.regions, kitchen.objects, goal, kitchen.skeletons,
                     kitchen.actions);
}

std::string to_json(const Tamp& tamp) {
  const TampOptions& options = *tamp.options;
  const TampResult& result = *tamp.result;
  const MonteCarloResult& summary = result.summary;
  Json out;
  out["domain"] = tamp.domain;
  out["world"] = tamp.world;
  out["library"] = tamp.library;
  out["solver"] = options.solver;
  out["parameters"] = parameters_object(options.solver, options.parameters);
  if (options.acting == Acting::concurrent) {
    // Only when acting while planning (SPEC §10), so that plan-first reports stay as they were.
    out["acting"] = acting_name(Acting::concurrent);
    out["commit_rule"] = allocator_registry().find(options.solver).commit_rule;
  }
  out["deadline_seconds"] = deadline_seconds(result);
  out["deadline_steps"] = result.deadline_steps;
  out["step_seconds"] = result.step_seconds;
  out["task_seconds"] = options.task_seconds;
  out["arrival_period"] = options.arrival_period;
  out["max_skeletons"] = options.max_skeletons;
  out["effort"] = effort_unit_name(options.effort.unit);
  out["decision_share"] = options.decision_share;
  out["clock"] = options.thinking ? "model" : "real";
  if (options.thinking) {
    out["decision_seconds"] = options.thinking->seconds_per_decision;
    out["iteration_seconds"] = options.thinking->seconds_per_iteration;
  }
  out["episodes"] = summary.episodes;
  out["seed"] = options.seed;
  out["successes"] = summary.successes;
  out["success_rate"] = summary.success_rate;
  out["ci95"] = summary.ci95;
  out["mean_skeletons_found"] = result.mean_skeletons_found;
  out["refinements_started"] = result.refinements_started;
  out["backtracks"] = result.backtracks;
  out["seconds"] = summary.seconds;
  add_charges(out, summary.live_mean, "mean_");
  if (options.adaptation) {
    // Episode e of every sequence: how many succeeded, and the rate with its interval.
    Json adaptation;
    adaptation["strength"] = options.adaptation->strength;
    adaptation["sequences"] = options.adaptation->sequences;
    adaptation["episodes_per_sequence"] = options.episodes;
    Json by_episode = Json::array();
    for (const std::uint64_t successes : result.successes_by_episode) {
      const double rate = static_cast<double>(successes) / static_cast<double>(options.adaptation->sequences);
      by_episode.push_back({{"successes", successes},
                            {"success_rate", rate},
                            {"ci95", ci95_half_width(rate, options.adaptation->sequences)}});
    }
    adaptation["by_episode"] = std::move(by_episode);
    out["adaptation"] = std::move(adaptation);
  }
  out["episode_results"] = live_episodes(result.episodes, true);
  return dump(out);
}

std::string to_text(const Tamp& tamp) {
  const TampOptions& options = *tamp.options;
  const TampResult& result = *tamp.result;
  const MonteCarloResult& summary = result.summary;
  std::string out = fmt::format("solver               {} on {} ({} s deadline = {} steps of {} s)\n", options.solver,
                                tamp.world, deadline_seconds(result), result.deadline_steps, result.step_seconds);
  if (options.acting == Acting::concurrent) {
    out += fmt::format("acting               concurrent (SPEC §10); commit rule: {}\n",
                       allocator_registry().find(options.solver).commit_rule);
  }
  out += fmt::format("success              {:.4f} ± {:.4f}  ({} of {} episodes, seed {}, {:.1f} s)\n",
                     summary.success_rate, summary.ci95, summary.successes, summary.episodes, options.seed,
                     summary.seconds);
  out += fmt::format("skeletons found      {:.2f} per episode (at most {}, {} s of search each, one every {} steps)\n",
                     result.mean_skeletons_found, options.max_skeletons, options.task_seconds, options.arrival_period);
  out += fmt::format(
      "charged per episode  thinking {:.3f} s, planning {:.3f} s (overruns {:.3f} s), search and outside {:.3f} s: "
      "{:.3f} s of {:.1f} s\n",
      summary.live_mean.decision, summary.live_mean.planning, summary.live_mean.overrun, summary.live_mean.outside,
      summary.live_mean.elapsed, deadline_seconds(result));
  out += fmt::format("refinements started  {:.2f} per episode\n", result.refinements_started);
  if (result.backtracks > 0) out += fmt::format("backtracks           {:.2f} per episode\n", result.backtracks);
  if (options.adaptation) {
    const auto sequences = static_cast<double>(options.adaptation->sequences);
    out += fmt::format("online update        {} sequences of {} episodes, the library a prior of strength {}\n",
                       options.adaptation->sequences, options.episodes, options.adaptation->strength);
    out += "success by episode  ";
    for (std::size_t e = 0; e < result.successes_by_episode.size(); ++e) {
      out += fmt::format(" {}:{:.3f}", e + 1, static_cast<double>(result.successes_by_episode[e]) / sequences);
    }
    out += "\n";
  }
  if (options.thinking) {
    out += fmt::format("clock                model: {} s per decision, {} s per search iteration; nothing real\n",
                       options.thinking->seconds_per_decision, options.thinking->seconds_per_iteration);
  } else {
    out += "clock                real (thinking and search as measured; --clock model to reproduce)\n";
  }
  if (options.picture_episode && !tamp.picture_files.empty()) {
    out += fmt::format("picture              episode {}: {}\n", *options.picture_episode, tamp.picture_files);
  }
  return out;
}

std::string picture_json(const TampPicture& picture) {
  Json out;
  out["episode"] = picture.episode;
  out["drawing"] = episode_drawing_object(picture.drawing);
  out["timeline_csv"] = timeline_csv(*picture.result.problem, picture.result);
  return dump(out);
}

std::string to_json(const Run& run) {
  const PlannerRunOptions& options = *run.options;
  const PlannerRun& result = *run.result;
  const MonteCarloResult& summary = result.summary;
  const bool live = is_live(options);
  Json out;
  out["domain"] = run.domain;
  out["instance"] = run.instance;
  out["solver"] = options.solver;
  out["parameters"] = parameters_object(options.solver, options.parameters);
  if (run.problem->acting() == Acting::concurrent) {
    // Only when acting while planning (SPEC §10), so that plan-first reports stay as they were.
    out["acting"] = acting_name(Acting::concurrent);
    out["commit_rule"] = allocator_registry().find(options.solver).commit_rule;
  }
  out["episodes"] = summary.episodes;
  out["seed"] = options.seed;
  out["successes"] = summary.successes;
  out["success_rate"] = summary.success_rate;
  out["ci95"] = summary.ci95;
  out["independent_starts"] = options.independent_starts;
  out["refinements_started"] = result.refinements_started;
  out["backtracks"] = result.backtracks;
  if (options.belief != nullptr) out["belief"] = options.belief_source;
  out["seconds"] = summary.seconds;
  if (result.exact) out["model_exact_success_probability"] = result.exact->success_probability;
  out["effort"] = effort_unit_name(options.effort.unit);
  out["live"] = live;
  if (live) {
    out["decision_share"] = options.decision_share;
    if (run.problem->acting() != Acting::concurrent) {
      // A live concurrent session has no step clock beside it: its starts depend on the seconds.
      out["step_clock_successes"] = summary.model_successes;
      out["step_clock_undecided"] = summary.model_undecided;
    }
    add_charges(out, summary.live_mean, "mean_");
    out["episode_results"] = live_episodes(result.episodes, false);
  }
  return dump(out);
}

std::string to_text(const Run& run) {
  const PlannerRunOptions& options = *run.options;
  const PlannerRun& result = *run.result;
  const MonteCarloResult& summary = result.summary;
  const bool live = is_live(options);
  std::string out =
      fmt::format("solver               {} on the {} domain (model {}{})\n", options.solver, run.domain, run.instance,
                  options.belief == nullptr ? "" : ", deciding with the distributions of " + options.belief_source);
  if (run.problem->acting() == Acting::concurrent) {
    out += fmt::format("acting               concurrent (SPEC §10); commit rule: {}\n",
                       allocator_registry().find(options.solver).commit_rule);
  }
  out += fmt::format("real planner         {:.4f} ± {:.4f}  ({} of {} episodes, seed {}, {:.1f} s){}\n",
                     summary.success_rate, summary.ci95, summary.successes, summary.episodes, options.seed,
                     summary.seconds, live ? ", live" : "");
  if (live && run.problem->acting() != Acting::concurrent) {
    out += fmt::format(
        "same calls, steps    {:.4f}  ({} of {} by the model's step clock; {} undecided when the live episode "
        "ended)\n",
        static_cast<double>(summary.model_successes) / static_cast<double>(summary.episodes), summary.model_successes,
        summary.episodes, summary.model_undecided);
  }
  if (live) {
    out += fmt::format(
        "charged per episode  thinking {:.3f} s, planning {:.3f} s (overruns {:.3f} s): {:.3f} s of {:.1f} s\n",
        summary.live_mean.decision, summary.live_mean.planning, summary.live_mean.overrun, summary.live_mean.elapsed,
        run.problem->deadline() * run.problem->step_seconds());
  }
  if (run.timeline_episode) {
    out += fmt::format("timeline             episode {}: {}\n", *run.timeline_episode, run.timeline_files);
  }
  out += fmt::format("refinements started  {:.2f} per episode\n", result.refinements_started);
  if (result.backtracks > 0) out += fmt::format("backtracks           {:.2f} per episode\n", result.backtracks);
  if (result.exact) out += fmt::format("model, exact         {:.4f}\n", result.exact->success_probability);
  return out;
}

std::string to_json(const Collection& collection) {
  const CollectAndFitOptions& options = *collection.options;
  const CollectAndFitResult& result = *collection.result;
  Json out;
  out["domain"] = collection.domain;
  out["world"] = collection.world;
  out["trials"] = options.trials;
  out["every_action"] = options.every_action;
  out["seed"] = options.seed;
  out["effort"] = effort_unit_name(result.collection.effort.unit);
  out["step_seconds"] = result.collection.step_seconds;
  out["deadline"] = result.deadline;
  out["budget_steps"] = result.collection.budget_steps;
  out["checks_per_second"] = result.collection.effort.checks_per_second;
  out["attempts"] = result.result.log.size();
  out["found"] = result.found;
  out["collision_checks"] = result.result.collision_checks;
  out["seconds"] = result.result.seconds;
  out["resumed_attempts"] = result.resumed_attempts;
  out["log"] = options.log.string();
  out["instance"] = options.instance.string();
  out["actions"] = Json::parse(ontime::report::fit_json(*result.fit));
  return dump(out);
}

std::string to_text(const Collection& collection) {
  const CollectAndFitOptions& options = *collection.options;
  const CollectAndFitResult& result = *collection.result;
  std::string out = fmt::format("Collected {} attempts ({} per action, {} found) in {:.1f} s: {} collision checks.\n",
                                result.result.log.size(), options.trials, result.found, result.result.seconds,
                                result.result.collision_checks);
  if (result.resumed_attempts > 0) {
    out += fmt::format("Resumed from {}: {} attempts were done before.\n", result.checkpoint.string(),
                       result.resumed_attempts);
  }
  out += fmt::format("Log: {}. Instance: {} (deadline {} steps of {} s).\n\n", options.log.string(),
                     options.instance.string(), result.deadline, result.collection.step_seconds);
  out += ontime::report::fit_markdown(*result.fit);
  out += "\nT: planning steps, X: execution steps (means over the steps within the deadline).\n";
  return out;
}

}  // namespace ontime::domains::report
