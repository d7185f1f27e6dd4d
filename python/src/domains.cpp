// Bindings of the TAMP domains (OMPL, FCL, KDL): loading a domain, collecting its planner log and
// fitting its instance, running allocators against its real motion planner, the whole TAMP loop,
// its map and generated worlds — each the library function the command line calls (`ontime
// collect`, `run`, `tamp`, `map`, `generate-world`), with the command line's defaults, returning
// the domains report's JSON read back. Built only with the domains library
// (ONTIME_BUILD_DOMAINS); without it the submodule says so.

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "ontime/model/planner_log.hpp"

#ifdef ONTIME_PYTHON_DOMAINS
#include <filesystem>
#include <optional>

#include "ontime/domains/collect_and_fit.hpp"
#include "ontime/domains/collection.hpp"
#include "ontime/domains/drawing.hpp"
#include "ontime/domains/manipulation_generator.hpp"
#include "ontime/domains/navigation_generator.hpp"
#include "ontime/domains/planner_run.hpp"
#include "ontime/domains/predict.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/domains/report.hpp"
#include "ontime/domains/tamp.hpp"
#include "ontime/util/error.hpp"
#endif

namespace ontime::python {

#ifdef ONTIME_PYTHON_DOMAINS

namespace {

struct DomainHandle {
  std::string name;
  std::string world_file;
  domains::LoadedDomain loaded;
};

// Progress and Ctrl-C of a long library call: `progress` and `stop` hooks for run_interruptibly.
struct Hooks {
  std::function<void(std::uint64_t, std::uint64_t)> progress;
  std::function<bool()> stop;
};
Hooks hooks_of(const std::function<bool()>& stop, Progress& counters) {
  return {[&counters](std::uint64_t done, std::uint64_t total) {
            counters.done = done;
            counters.total = total;
          },
          stop};
}

// The collection's progress also stops it: the collection has no stop hook of its own.
std::function<void(std::uint64_t, std::uint64_t)> stopping_progress(const std::function<bool()>& stop,
                                                                    Progress& counters) {
  return [&stop, &counters](std::uint64_t done, std::uint64_t total) {
    if (stop()) throw Cancelled("collection stopped at the caller's request");
    counters.done = done;
    counters.total = total;
  };
}

using ChecksPerSecond = Number<double, "checks_per_second", 0.0>;
using StepSeconds = Number<double, "step_seconds", 0.0>;
using BudgetSteps = Number<Steps, "budget_steps", 0>;
using DecisionShare = Number<double, "decision_share", 0.0, 1e6>;

// What collect and collect_and_fit share: the trials and how they are run.
domains::CollectAndFitOptions collect_request(std::uint64_t trials, std::uint64_t seed, unsigned threads,
                                              const std::string& effort, double checks_per_second, double step_seconds,
                                              Steps budget_steps, bool every_action, bool features) {
  domains::CollectAndFitOptions request;
  request.trials = trials;
  request.seed = seed;
  request.threads = threads;
  request.effort = effort;
  request.checks_per_second = checks_per_second;
  request.step_seconds = step_seconds;
  request.budget = budget_steps;
  request.every_action = every_action;
  request.features = features;
  return request;
}

}  // namespace

void bind_domains(py::module_& m) {
  m.attr("available") = true;
  m.def("names", &domains::domain_names, "The domains that can be loaded: navigation, manipulation.");

  py::class_<DomainHandle, std::shared_ptr<DomainHandle>>(m, "Domain", "A TAMP domain loaded from its world file.")
      .def_property_readonly("name", [](const DomainHandle& d) { return d.name; })
      .def_property_readonly("world_file", [](const DomainHandle& d) { return d.world_file; })
      .def_property_readonly(
          "skeletons", [](const DomainHandle& d) { return d.loaded.domain->skeletons(); },
          "The plan skeletons as lists of action ids.")
      .def_property_readonly(
          "defaults",
          [](const DomainHandle& d) {
            py::dict out;
            out["deadline"] = d.loaded.defaults.collection.deadline;
            out["step_seconds"] = d.loaded.defaults.collection.step_seconds;
            out["checks_per_second"] = d.loaded.defaults.collection.checks_per_second;
            return out;
          },
          "The world file's collection settings: deadline (steps), step_seconds, checks_per_second.")
      .def("__repr__", [](const DomainHandle& d) { return "ontime.domains.Domain('" + d.name + "')"; });

  m.def(
      "load",
      [](const std::string& name, const py::object& world_file) {
        auto handle = std::make_shared<DomainHandle>();
        handle->name = name;
        handle->world_file = path_argument(world_file, "world_file");
        const py::gil_scoped_release release;
        handle->loaded = domains::load_domain(name, handle->world_file);
        return handle;
      },
      py::arg("name"), py::arg("world_file"),
      "Loads the domain `name` from its world file (e.g. data/domains/navigation.json). Raises UsageError for "
      "an unknown name, InputError for a bad world file.");

  m.def(
      "collect",
      [](const Required<DomainHandle, "domain">& domain, Number<std::uint64_t, "trials", 1> trials, Seed seed,
         Threads threads, const std::string& effort, ChecksPerSecond checks_per_second, StepSeconds step_seconds,
         BudgetSteps budget_steps, bool every_action, bool features, const py::object& progress) {
        check_callable(progress, "progress");
        const domains::CollectAndFitOptions request = collect_request(
            trials, seed, threads, effort, checks_per_second, step_seconds, budget_steps, every_action, features);
        domains::CollectionOptions options = domains::collection_options(domain->loaded.defaults, request);
        options.world_name = std::filesystem::path(domain->world_file).stem().string();
        domains::CollectionResult result;
        run_interruptibly(
            [&](const std::function<bool()>& stop, Progress& counters) {
              options.progress = stopping_progress(stop, counters);
              result = domains::collect(*domain->loaded.domain, options);
            },
            progress);
        return attempts_list(result.log);
      },
      py::arg("domain"), py::kw_only(), py::arg("trials") = 1000, py::arg("seed") = 1, py::arg("threads") = 0,
      py::arg("effort") = "checks", py::arg("checks_per_second") = 0.0, py::arg("step_seconds") = 0.0,
      py::arg("budget_steps") = 0, py::arg("every_action").noconvert() = false, py::arg("features").noconvert() = false,
      py::arg("progress") = py::none(),
      "Refines every action of the domain's skeleton tree (every_action=True: every action the domain can "
      "refine, each on its own; features=True: every record carries the world and the action's feature vector) "
      "`trials` times and returns the planner log as records (write it with "
      "ontime.write_planner_log, fit it with ontime.fit). The same log as `ontime collect` for the same seed, "
      "whatever `threads` (effort 'checks'). 0 means the world file's setting (step_seconds, checks_per_second) "
      "or its deadline (budget_steps, the cut-off).");

  m.def(
      "collect_and_fit",
      [](const Required<DomainHandle, "domain">& domain, const py::object& log, const py::object& instance,
         Number<std::uint64_t, "trials", 1> trials, Seed seed, Threads threads, const std::string& effort,
         ChecksPerSecond checks_per_second, StepSeconds step_seconds,
         Number<Steps, "deadline", 0, Problem::kMaxDeadline> deadline, BudgetSteps budget_steps,
         Number<double, "laplace", 0.0> laplace, bool every_action, bool features, const std::string& log_format,
         const py::object& checkpoint, bool resume, const py::object& progress) {
        check_callable(progress, "progress");
        domains::CollectAndFitOptions options = collect_request(trials, seed, threads, effort, checks_per_second,
                                                                step_seconds, budget_steps, every_action, features);
        options.deadline = deadline;
        options.laplace = laplace;
        options.log_format = log_format;
        options.log = path_argument(log, "log");
        options.instance = path_argument(instance, "instance");
        if (!checkpoint.is_none()) options.checkpoint = path_argument(checkpoint, "checkpoint");
        options.resume = resume;
        domains::CollectAndFitResult result;
        run_interruptibly(
            [&](const std::function<bool()>& stop, Progress& counters) {
              options.progress = stopping_progress(stop, counters);
              result = domains::collect_and_fit(*domain->loaded.domain, domain->loaded.defaults, domain->world_file,
                                                options, python_spelling());
            },
            progress);
        return json_object(domains::report::to_json(domains::report::Collection{
            .domain = domain->name, .world = domain->world_file, .options = &options, .result = &result}));
      },
      py::arg("domain"), py::arg("log"), py::arg("instance"), py::kw_only(), py::arg("trials") = 1000,
      py::arg("seed") = 1, py::arg("threads") = 0, py::arg("effort") = "checks", py::arg("checks_per_second") = 0.0,
      py::arg("step_seconds") = 0.0, py::arg("deadline") = 0, py::arg("budget_steps") = 0, py::arg("laplace") = 0.0,
      py::arg("every_action").noconvert() = false, py::arg("features").noconvert() = false,
      py::arg("log_format") = "jsonl", py::arg("checkpoint") = py::none(), py::arg("resume").noconvert() = false,
      py::arg("progress") = py::none(),
      "`ontime collect`: collects as collect() does, writes the planner log to `log` (log_format 'jsonl' or "
      "'ompl-benchmark'), fits the instance (deadline steps; 0: the world file's) and writes it to `instance`; "
      "returns the fields of `ontime collect --json`. Finished trials go to `checkpoint` (default: the log's "
      "path followed by .checkpoint) until the files are written; resume=True continues an interrupted "
      "collection to the same files.");

  m.def(
      "run",
      [](const Required<DomainHandle, "domain">& domain, const py::object& problem, const std::string& solver,
         Episodes episodes, Seed seed, Threads threads, const std::string& effort, ChecksPerSecond checks_per_second,
         bool independent_starts, bool exact, bool live, DecisionShare decision_share, const py::object& belief,
         const py::object& progress, const std::optional<std::string>& act, const py::kwargs& kwargs) {
        check_callable(progress, "progress");
        // Read as a problem: one acting while planning (SPEC §10) makes no plan-first Mdp.
        const std::shared_ptr<const Problem> chosen = problem_with_acting(problem, act);
        const std::string instance = instance_label(problem, *chosen);
        std::shared_ptr<const Problem> believed;  // (read as a problem too, whatever its acting mode)
        domains::PlannerRunOptions options;
        if (!belief.is_none()) {
          believed = problem_with_acting(belief, {}, "belief");
          try {
            (void)with_distributions_of(*chosen, *believed);
          } catch (const UsageError& error) {
            throw UsageError(std::string("belief: ") + error.what());
          }
          options.belief = believed.get();
          options.belief_source = instance_label(belief, *believed);
        }
        options.solver = solver;
        options.parameters = parameter_values(kwargs);
        options.episodes = episodes;
        options.seed = seed;
        options.threads = threads;
        options.effort = domains::effort_settings(domain->loaded.defaults, effort, checks_per_second);
        options.independent_starts = independent_starts;
        options.exact = exact;
        options.live = live;
        options.decision_share = decision_share;
        domains::check_planner_run_request(*chosen, instance, options, python_spelling());
        domains::check_domain_actions(*domain->loaded.domain, *chosen, instance);
        domains::PlannerRun result;
        run_interruptibly(
            [&](const std::function<bool()>& stop, Progress& counters) {
              const Hooks hooks = hooks_of(stop, counters);
              options.progress = hooks.progress;
              options.stop = hooks.stop;
              result = domains::run_planner_episodes(*domain->loaded.domain, *chosen, options);
            },
            progress);
        return json_object(domains::report::to_json(domains::report::Run{.domain = domain->name,
                                                                         .instance = instance,
                                                                         .problem = chosen.get(),
                                                                         .options = &options,
                                                                         .result = &result}));
      },
      py::arg("domain"), py::arg("problem"), py::arg("solver"), py::kw_only(), py::arg("episodes") = 200,
      py::arg("seed") = 1, py::arg("threads") = 0, py::arg("effort") = "checks", py::arg("checks_per_second") = 0.0,
      py::arg("independent_starts").noconvert() = false, py::arg("exact").noconvert() = false,
      py::arg("live").noconvert() = false, py::arg("decision_share") = 0.5, py::arg("belief") = py::none(),
      py::arg("progress") = py::none(), py::arg("act") = py::none(),
      "`ontime run`: episodes in which the allocator `solver` (parameters as keyword arguments), with `problem` "
      "as its model, drives the domain's real motion planner; live=True (always with effort 'wall') charges "
      "its thinking and the planner's overruns on the clock; `belief` (a Problem or instance file): the "
      "allocator decides with its distributions, `problem`'s skeletons and culprits kept (`ontime run "
      "--belief`); act='concurrent' (or a problem acting while planning): the robot executes each motion it "
      "starts while the planner refines the next (`ontime run --act`). Returns the fields of `ontime run --json` "
      "(live: every episode with its timeline and, acting while planning, the robot's executions).");

  m.def(
      "tamp",
      [](const Required<DomainHandle, "domain">& domain, const py::object& library, const std::string& solver,
         Number<double, "deadline", 1e-9> deadline, Number<std::uint64_t, "episodes", 1> episodes, Seed seed,
         Threads threads, const std::string& effort, Number<double, "task_seconds", 0.0, 1e6> task_seconds,
         Number<int, "arrival_period", 1, 10'000> arrival_period,
         Number<int, "max_skeletons", 1, Problem::kMaxSkeletons> max_skeletons, DecisionShare decision_share,
         const std::string& clock, std::optional<Number<double, "decision_seconds", 0.0, 1e6>> decision_seconds,
         std::optional<Number<double, "iteration_seconds", 1e-12, 1e6>> iteration_seconds,
         std::optional<Number<std::uint64_t, "picture_episode">> picture_episode,
         std::optional<Number<double, "adapt_strength", 1e-9, 1e9>> adapt_strength,
         Number<std::uint64_t, "sequences", 1> sequences, const py::object& progress,
         const std::optional<std::string>& act, const py::kwargs& kwargs) {
        check_callable(progress, "progress");
        if (clock != "real" && clock != "model") {
          throw UsageError("clock must be 'real' or 'model' (got '" + clock + "')");
        }
        if (clock == "real" && (decision_seconds || iteration_seconds)) {
          throw UsageError("decision_seconds and iteration_seconds need clock='model'");
        }
        // Read as a problem: a library acting while planning (SPEC §10) makes no plan-first Mdp.
        const std::shared_ptr<const Problem> chosen = problem_with_acting(library, act, "library");
        domains::TampOptions options;
        options.acting = chosen->acting();
        options.solver = solver;
        options.parameters = parameter_values(kwargs);
        options.deadline = deadline;
        options.effort = domains::effort_settings(domain->loaded.defaults, effort);
        options.episodes = episodes;
        options.seed = seed;
        options.threads = threads;
        options.task_seconds = task_seconds;
        options.arrival_period = arrival_period;
        options.max_skeletons = max_skeletons;
        options.decision_share = decision_share;
        if (clock == "model") {
          ThinkingModel thinking;
          if (decision_seconds) thinking.seconds_per_decision = *decision_seconds;
          if (iteration_seconds) thinking.seconds_per_iteration = *iteration_seconds;
          options.thinking = thinking;
        }
        options.keep_episodes = true;
        if (picture_episode) options.picture_episode = *picture_episode;
        if (adapt_strength) {
          options.adaptation = domains::TampAdaptation{.strength = *adapt_strength, .sequences = sequences};
        } else if (sequences != 1) {
          throw UsageError("sequences needs adapt_strength");
        }
        options.world_name = std::filesystem::path(domain->world_file).filename().string();
        options.library_source = instance_label(library, *chosen);
        domains::TampResult result;
        run_interruptibly(
            [&](const std::function<bool()>& stop, Progress& counters) {
              const Hooks hooks = hooks_of(stop, counters);
              options.progress = hooks.progress;
              options.stop = hooks.stop;
              result = domains::run_tamp(*domain->loaded.domain, *chosen, options, python_spelling());
            },
            progress);
        py::dict out = json_object(domains::report::to_json(domains::report::Tamp{.domain = domain->name,
                                                                                  .world = domain->world_file,
                                                                                  .library = options.library_source,
                                                                                  .options = &options,
                                                                                  .result = &result}));
        if (result.picture) out["picture"] = json_object(domains::report::picture_json(*result.picture));
        return out;
      },
      py::arg("domain"), py::arg("library"), py::arg("solver"), py::arg("deadline"), py::kw_only(),
      py::arg("episodes") = 100, py::arg("seed") = 1, py::arg("threads") = 0, py::arg("effort") = "checks",
      py::arg("task_seconds") = 0.5, py::arg("arrival_period") = 2, py::arg("max_skeletons") = 16,
      py::arg("decision_share") = 0.5, py::arg("clock") = "real", py::arg("decision_seconds") = py::none(),
      py::arg("iteration_seconds") = py::none(), py::arg("picture_episode") = py::none(),
      py::arg("adapt_strength") = py::none(), py::arg("sequences") = 1, py::arg("progress") = py::none(),
      py::arg("act") = py::none(),
      "`ontime tamp`: the whole TAMP loop on the clock. The domain's task planner streams skeletons (at most "
      "max_skeletons, each charged task_seconds of search, one every arrival_period steps), the allocator "
      "`solver` (parameters as keyword arguments) decides which action the real motion planner refines next, "
      "with the distributions of `library` (a Problem or an instance path whose actions are the domain's). "
      "`deadline` in seconds. clock='model' charges thinking by decision_seconds and iteration_seconds, so that "
      "the same seed gives the same episodes on any machine. Returns the fields of `ontime tamp --json`; with "
      "picture_episode, also 'picture': that episode's drawing (what plot_tamp.py draws) and timeline CSV. "
      "adapt_strength: `sequences` sequences of `episodes` episodes that learn as they go (`--adapt-strength`): "
      "each episode plans with the library updated by the attempts of its sequence's episodes before, the "
      "library a prior worth adapt_strength attempts; 'adaptation' gives the success rate by episode. "
      "act='concurrent' (default: the library's acting): the robot acts while planning (`--act`, SPEC §10), the "
      "task planner streaming only paths through what it executed after each start.");

  m.def(
      "map_data",
      [](const Required<DomainHandle, "domain">& domain, Seed seed) {
        domains::MapDrawing drawing;
        {
          const py::gil_scoped_release release;
          drawing = domains::map_drawing(*domain->loaded.domain, domain->loaded.defaults, seed);
        }
        return json_object(domains::report::to_json(drawing));
      },
      py::arg("domain"), py::kw_only(), py::arg("seed") = 1,
      "`ontime map`'s drawing: the domain's world and one refined motion per skeleton (stream k of `seed` for "
      "skeleton k), the JSON the command writes beside its picture (python/plot_map.py draws it).");

  m.def(
      "feature_names", [](const std::string& name) { return domains::domain_feature_names(name); }, py::arg("name"),
      "The names of a domain's action features (what `fit --conditional --domain NAME` records).");

  m.def(
      "features",
      [](const Required<DomainHandle, "domain">& domain, const std::string& action) {
        std::vector<double> values;
        try {
          values = domain->loaded.domain->action_features(action);
        } catch (const std::invalid_argument& error) {
          throw UsageError(error.what());
        }
        return py::array_t<double>(static_cast<py::ssize_t>(values.size()), values.data());
      },
      py::arg("domain"), py::arg("action"),
      "The action's feature vector in the domain's world (numpy), in the order of feature_names(domain.name).");

  m.def(
      "predict",
      [](const Required<DomainHandle, "domain">& domain, const Required<ConditionalTimeModel, "model">& model,
         Number<Steps, "deadline", 0, Problem::kMaxDeadline> deadline, bool library, const std::string& name,
         Threads threads) {
        domains::PredictOptions options;
        options.deadline = deadline;
        options.library = library;
        options.name = name;
        options.threads = threads;
        const py::gil_scoped_release release;
        return std::make_shared<Problem>(
            domains::predict_instance(*domain->loaded.domain, domain->loaded.defaults, *model, options));
      },
      py::arg("domain"), py::arg("model"), py::kw_only(), py::arg("deadline") = 0,
      py::arg("library").noconvert() = false, py::arg("name") = "", py::arg("threads") = 0,
      "`ontime predict`: the instance of the domain's world with every action's distributions predicted by the "
      "conditional time model (the world's skeletons, or every action on its own with library=True or a world "
      "without skeletons); deadline 0: the world file's. The actions' features are computed on `threads` threads "
      "(0: one per hardware thread; the instance is the same for every count).");

  m.def(
      "generate_world",
      [](const py::object& output, Number<int, "rows", 1, domains::kMaxBuildingSide> rows,
         Number<int, "cols", 1, domains::kMaxBuildingSide> cols,
         Number<double, "room_size", domains::kMinBuildingRoomSize, domains::kMaxBuildingRoomSize> room_size,
         Number<double, "door_density", 0.0, 1.0> door_density, Number<double, "narrow_doors", 0.0, 1.0> narrow_doors,
         Number<double, "narrow_min", domains::kMinBuildingDoorWidth, domains::kMaxBuildingDoorWidth> narrow_min,
         Number<double, "narrow_max", domains::kMinBuildingDoorWidth, domains::kMaxBuildingDoorWidth> narrow_max,
         Number<double, "wide_min", domains::kMinBuildingDoorWidth, domains::kMaxBuildingDoorWidth> wide_min,
         Number<double, "wide_max", domains::kMinBuildingDoorWidth, domains::kMaxBuildingDoorWidth> wide_max,
         Number<double, "empty_rooms", 0.0, 1.0> empty_rooms,
         Number<double, "cluttered_rooms", 0.0, 1.0> cluttered_rooms,
         Number<int, "min_boxes", 0, domains::kMaxBuildingBoxes> min_boxes,
         Number<int, "max_boxes", 0, domains::kMaxBuildingBoxes> max_boxes,
         Number<int, "skeletons", 0, domains::kMaxBuildingSkeletons> skeletons, Seed seed,
         const std::optional<std::string>& name) {
        // Ranges given backwards are named here: the generator names them as the command line spells them.
        const auto ordered = [](double low, double high, const char* low_name, const char* high_name) {
          if (low > high) {
            throw UsageError("parameter '" + std::string(low_name) + "': must not exceed " + high_name + " (" +
                             std::string(py::str(py::float_(high))) + ") (got " +
                             std::string(py::str(py::float_(low))) + ")");
          }
        };
        ordered(narrow_min, narrow_max, "narrow_min", "narrow_max");
        ordered(wide_min, wide_max, "wide_min", "wide_max");
        ordered(min_boxes, max_boxes, "min_boxes", "max_boxes");
        if (empty_rooms + cluttered_rooms > 1) {
          throw UsageError("parameters 'empty_rooms' and 'cluttered_rooms': must sum to at most 1");
        }
        domains::BuildingOptions options;
        options.rows = rows;
        options.cols = cols;
        options.room_size = room_size;
        options.door_density = door_density;
        options.narrow_door_share = narrow_doors;
        options.narrow_width_min = narrow_min;
        options.narrow_width_max = narrow_max;
        options.wide_width_min = wide_min;
        options.wide_width_max = wide_max;
        options.empty_room_share = empty_rooms;
        options.cluttered_room_share = cluttered_rooms;
        options.min_boxes = min_boxes;
        options.max_boxes = max_boxes;
        options.skeletons = skeletons;
        options.seed = seed;
        if (name) options.name = *name;
        const std::string path = path_argument(output, "output");
        domains::GeneratedWorld world;
        {
          const py::gil_scoped_release release;
          world = domains::write_generated_world(options, path);
        }
        return json_object(domains::report::to_json(world));
      },
      py::arg("output"), py::kw_only(), py::arg("rows") = 6, py::arg("cols") = 5, py::arg("room_size") = 4.0,
      py::arg("door_density") = 0.8, py::arg("narrow_doors") = 0.2,
      py::arg("narrow_min") = domains::BuildingOptions{}.narrow_width_min,
      py::arg("narrow_max") = domains::BuildingOptions{}.narrow_width_max,
      py::arg("wide_min") = domains::BuildingOptions{}.wide_width_min,
      py::arg("wide_max") = domains::BuildingOptions{}.wide_width_max,
      py::arg("empty_rooms") = domains::BuildingOptions{}.empty_room_share,
      py::arg("cluttered_rooms") = domains::BuildingOptions{}.cluttered_room_share,
      py::arg("min_boxes") = domains::BuildingOptions{}.min_boxes,
      py::arg("max_boxes") = domains::BuildingOptions{}.max_boxes, py::arg("skeletons") = 0, py::arg("seed") = 1,
      py::arg("name") = py::none(),
      "`ontime generate-world`: writes a generated navigation world (an office building of rows x cols rooms) "
      "to `output` and returns what it holds (the fields of `ontime generate-world --json`). Same options, same "
      "seed: the same file.");

  m.def(
      "generate_kitchen",
      [](const py::object& output, Number<int, "tables", 1, domains::kMaxKitchenTables> tables,
         Number<int, "regions", 1, domains::kMaxKitchenRegions> regions,
         Number<double, "region_min", domains::kMinKitchenRegionSide, domains::kMaxKitchenRegionSide> region_min,
         Number<double, "region_max", domains::kMinKitchenRegionSide, domains::kMaxKitchenRegionSide> region_max,
         Number<int, "targets", 1, domains::kMaxKitchenTargets> targets,
         Number<int, "min_objects", 1, domains::kMaxKitchenObjects> min_objects,
         Number<int, "max_objects", 1, domains::kMaxKitchenObjects> max_objects,
         Number<int, "min_clutter", 0, domains::kMaxKitchenClutter> min_clutter,
         Number<int, "max_clutter", 0, domains::kMaxKitchenClutter> max_clutter,
         const std::vector<std::string>& classes, Seed seed, const std::optional<std::string>& name) {
        domains::KitchenOptions options;
        options.tables = tables;
        options.regions = regions;
        options.region_min = region_min;
        options.region_max = region_max;
        options.targets = targets;
        options.min_objects = min_objects;
        options.max_objects = max_objects;
        options.min_clutter = min_clutter;
        options.max_clutter = max_clutter;
        options.classes = classes;
        if (name) options.name = *name;
        const std::string path = path_argument(output, "output");
        domains::GeneratedKitchen kitchen;
        {
          const py::gil_scoped_release release;
          kitchen = domains::write_generated_kitchen(options, seed, path, python_spelling());
        }
        return json_object(domains::report::to_json(kitchen));
      },
      py::arg("output"), py::kw_only(), py::arg("tables") = domains::KitchenOptions{}.tables,
      py::arg("regions") = domains::KitchenOptions{}.regions,
      py::arg("region_min") = domains::KitchenOptions{}.region_min,
      py::arg("region_max") = domains::KitchenOptions{}.region_max,
      py::arg("targets") = domains::KitchenOptions{}.targets,
      py::arg("min_objects") = domains::KitchenOptions{}.min_objects,
      py::arg("max_objects") = domains::KitchenOptions{}.max_objects,
      py::arg("min_clutter") = domains::KitchenOptions{}.min_clutter,
      py::arg("max_clutter") = domains::KitchenOptions{}.max_clutter,
      py::arg("classes") = domains::KitchenOptions{}.classes, py::arg("seed") = 1, py::arg("name") = py::none(),
      "`ontime generate-world --domain manipulation` (ontime.domains.generate_world(..., domain='manipulation')): "
      "writes a generated kitchen (a table scene with its goal and skeletons) to `output` and returns what it "
      "holds (the fields of `ontime generate-world --domain manipulation --json`). Same options, same seed: the "
      "same file.");
}

#else

void bind_domains(py::module_& m) { m.attr("available") = false; }

#endif

}  // namespace ontime::python
