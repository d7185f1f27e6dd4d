// Bindings of the TAMP domains (OMPL, FCL, KDL): loading a domain, collecting its planner log and
// running allocators against its real motion planner, as `ontime collect` and `ontime run` do.
// Built only with the domains library (ONTIME_BUILD_DOMAINS); without it the submodule says so.

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/evaluation.hpp"

#ifdef ONTIME_PYTHON_DOMAINS
#include "ontime/allocators/optimal.hpp"
#include "ontime/domains/collection.hpp"
#include "ontime/domains/planner_world.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/util/error.hpp"
#endif

namespace ontime::python {

py::list attempts_list(const std::vector<RefinementAttempt>& attempts);
std::pair<MonteCarloResult, std::optional<ExactEvaluation>> run_and_evaluate(
    const MdpHandle& mdp, const WorldFactory& worlds, const AllocatorFactory& factory, const MonteCarloOptions& options,
    bool exact, const ParameterValues& values, const py::object& progress);

#ifdef ONTIME_PYTHON_DOMAINS

namespace {

struct DomainHandle {
  std::string name;
  std::string world_file;
  domains::LoadedDomain loaded;
};

domains::EffortSettings effort_of(const DomainHandle& domain, const std::string& unit, double checks_per_second) {
  domains::EffortSettings effort;
  effort.unit = domains::parse_effort_unit(unit);
  effort.checks_per_second =
      checks_per_second > 0 ? checks_per_second : domain.loaded.defaults.collection.checks_per_second;
  return effort;
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
        handle->world_file = py::str(py::module_::import("os").attr("fspath")(world_file));
        const py::gil_scoped_release release;
        handle->loaded = domains::load_domain(name, handle->world_file);
        return handle;
      },
      py::arg("name"), py::arg("world_file"),
      "Loads the domain `name` from its world file (e.g. data/domains/navigation.json). Raises UsageError for "
      "an unknown name, InputError for a bad world file.");

  m.def(
      "collect",
      [](const std::shared_ptr<DomainHandle>& domain, Number<std::uint64_t, "trials", 1> trials, Seed seed,
         Threads threads, const std::string& effort, Number<double, "checks_per_second", 0.0> checks_per_second,
         Number<double, "step_seconds", 0.0> step_seconds, Number<Steps, "budget_steps", 0> budget_steps,
         const py::object& progress) {
        if (trials == 0) throw UsageError("trials must be at least 1");
        domains::CollectionOptions options;
        options.trials = trials;
        options.seed = seed;
        options.threads = threads;
        options.effort = effort_of(*domain, effort, checks_per_second);
        const domains::CollectionDefaults& defaults = domain->loaded.defaults.collection;
        options.step_seconds = step_seconds > 0 ? step_seconds : defaults.step_seconds;
        options.budget_steps = budget_steps > 0 ? budget_steps : defaults.deadline;
        domains::CollectionResult result;
        run_interruptibly(
            [&](const std::function<bool()>& stop, Progress& counters) {
              options.progress = [&](std::uint64_t done, std::uint64_t total) {
                if (stop()) throw Cancelled("collection stopped at the caller's request");
                counters.done = done;
                counters.total = total;
              };
              result = domains::collect(*domain->loaded.domain, options);
            },
            progress);
        return attempts_list(result.log);
      },
      py::arg("domain"), py::kw_only(), py::arg("trials") = 1000, py::arg("seed") = 1, py::arg("threads") = 0,
      py::arg("effort") = "checks", py::arg("checks_per_second") = 0.0, py::arg("step_seconds") = 0.0,
      py::arg("budget_steps") = 0, py::arg("progress") = py::none(),
      "Refines every action of the domain's skeleton tree `trials` times and returns the planner log as "
      "records (write it with ontime.write_planner_log, fit it with ontime.fit). The same log as `ontime "
      "collect` for the same seed, whatever `threads` (effort 'checks'). 0 means the world file's setting "
      "(step_seconds, checks_per_second) or its deadline (budget_steps, the cut-off).");

  m.def(
      "run",
      [](const std::shared_ptr<DomainHandle>& domain, const py::object& problem, const std::string& solver,
         Episodes episodes, Seed seed, Threads threads, const std::string& effort,
         Number<double, "checks_per_second", 0.0> checks_per_second, bool independent_starts, bool exact,
         const py::object& progress, const py::kwargs& kwargs) {
        if (episodes == 0) throw UsageError("episodes must be at least 1");
        const std::shared_ptr<MdpHandle> mdp = to_mdp(problem);
        const ParameterValues values = parameter_values(kwargs);
        domains::PlannerWorldOptions planner;
        planner.effort = effort_of(*domain, effort, checks_per_second);
        planner.independent_starts = independent_starts;
        const AllocatorFactory factory = [&] {
          const py::gil_scoped_release release;
          return make_allocator_factory(solver, mdp->mdp, values);
        }();
        MonteCarloOptions options;
        options.episodes = episodes;
        options.seed = seed;
        options.threads = threads;
        const auto [result, exact_result] =
            run_and_evaluate(*mdp, domains::planner_worlds(*domain->loaded.domain, *mdp->problem, planner), factory,
                             options, exact, values, progress);
        py::dict out =
            monte_carlo_dict(solver, values, instance_label(problem, *mdp->problem), *mdp->problem, result, seed);
        out["domain"] = domain->name;
        out["independent_starts"] = independent_starts;
        out["refinements_started"] =
            result.world_statistics.find("refinements_started").value_or(0.0) / static_cast<double>(result.episodes);
        if (exact_result) out["model_exact_success_probability"] = exact_result->success_probability;
        return out;
      },
      py::arg("domain"), py::arg("problem"), py::arg("solver"), py::kw_only(), py::arg("episodes") = 200,
      py::arg("seed") = 1, py::arg("threads") = 0, py::arg("effort") = "checks", py::arg("checks_per_second") = 0.0,
      py::arg("independent_starts") = false, py::arg("exact") = false, py::arg("progress") = py::none(),
      "Episodes in which the allocator `solver` (parameters as keyword arguments), with `problem` as its model, "
      "drives the domain's real motion planner; the fields of `ontime run --json`.");
}

#else

void bind_domains(py::module_& m) { m.attr("available") = false; }

#endif

}  // namespace ontime::python
