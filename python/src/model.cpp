// Bindings of the model layer: distributions, problems, the MDP and its states, planner logs and
// fitting, and the allocator registry's description of itself.

#include <pybind11/numpy.h>
#include <pybind11/operators.h>
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <sstream>

#include "bindings.hpp"
#include "ontime/learn/fitting.hpp"
#include "ontime/learn/log_sampling.hpp"
#include "ontime/mdp/state.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/model/skeleton_file.hpp"
#include "ontime/report/report.hpp"
#include "ontime/solve/knapsack.hpp"
#include "ontime/util/error.hpp"

namespace ontime::python {

namespace {

std::vector<double> to_vector(const py::array_t<double, py::array::c_style | py::array::forcecast>& values) {
  if (values.ndim() != 1) throw UsageError("a distribution is a one-dimensional array of probabilities");
  return {values.data(), values.data() + values.size()};
}

py::object step_or_none(Steps step) { return step == kNever ? py::none() : py::object(py::int_(step)); }

template <class Array>
py::list first(const Array& values, int count) {
  py::list out;
  for (int k = 0; k < count; ++k) out.append(values[static_cast<std::size_t>(k)]);
  return out;
}

py::dict attempt_dict(const RefinementAttempt& attempt) {
  py::dict out;
  out["action"] = attempt.action;
  out["planning_seconds"] = attempt.planning_seconds;
  out["found"] = attempt.found;
  if (attempt.found) out["execution_seconds"] = attempt.execution_seconds;
  if (attempt.trial) out["trial"] = *attempt.trial;
  if (attempt.collision_checks) out["collision_checks"] = *attempt.collision_checks;
  return out;
}

}  // namespace

py::list attempts_list(const std::vector<RefinementAttempt>& attempts) {
  py::list out;
  for (const RefinementAttempt& attempt : attempts) out.append(attempt_dict(attempt));
  return out;
}

void bind_model(py::module_& m) {
  py::class_<Distribution>(m, "Distribution",
                           "A distribution over whole time steps; mass the listed steps do not cover is \"never\".")
      .def_static(
          "from_pmf",
          [](const py::array_t<double, py::array::c_style | py::array::forcecast>& masses) {
            return Distribution::from_pmf(to_vector(masses));
          },
          py::arg("masses"), "From probabilities: masses[t] = P(T = t). Raises UsageError for a bad table.")
      .def_static(
          "from_cdf",
          [](const py::array_t<double, py::array::c_style | py::array::forcecast>& cumulative) {
            return Distribution::from_cdf(to_vector(cumulative));
          },
          py::arg("cumulative"), "From cumulative probabilities: cumulative[t] = P(T <= t).")
      .def_property_readonly(
          "pmf",
          [](const Distribution& d) {
            const auto masses = d.masses();
            return py::array_t<double>(static_cast<py::ssize_t>(masses.size()), masses.data());
          },
          "P(T = t) for t = 0, 1, ... as a numpy array (zero beyond its end).")
      .def_property_readonly("never", &Distribution::never, "P(T is never): the mass no listed step covers.")
      .def(
          "cdf", [](const Distribution& d, Number<Steps, "t"> t) { return d.cdf(t); }, py::arg("t"), "P(T <= t).")
      .def(
          "survival", [](const Distribution& d, Number<Steps, "t"> t) { return d.survival(t); }, py::arg("t"),
          "P(T > t), \"never\" included.")
      .def("hazard", &Distribution::hazard, py::arg("spent"),
           "P(T = spent + 1 | T > spent): the chance that one more step finishes.")
      .def("mean_finite", &Distribution::mean_finite, "E[T | T finite] (inf when nothing is finite).")
      .def_property_readonly(
          "min_step", [](const Distribution& d) { return step_or_none(d.min_step()); },
          "Smallest step with positive mass, or None.")
      .def_property_readonly(
          "max_step", [](const Distribution& d) { return step_or_none(d.max_step()); },
          "Largest step with positive mass, or None.")
      .def(
          "quantile",
          [](const Distribution& d, Number<double, "u", 0.0, 1.0> u) { return step_or_none(d.quantile(u)); },
          py::arg("u"),
          "The smallest t with cdf(t) > u, or None (\"never\").")
      .def(py::self == py::self)  // NOLINT(misc-redundant-expression)
      .def("__repr__", [](const Distribution& d) {
        std::ostringstream text;
        text << "ontime.Distribution(pmf of " << d.masses().size() << " steps, never=" << d.never() << ")";
        return text.str();
      });

  py::class_<Action>(m, "Action", "An abstract action with its planning- and execution-time distributions.")
      .def_readonly("id", &Action::id, "The action's id, e.g. 'move(R1,R5)'.")
      .def_readonly("planning", &Action::planning, "Steps of effort until refined (t >= 1).")
      .def_readonly("execution", &Action::execution, "Steps to execute the refined motion (x >= 0).")
      .def("__repr__", [](const Action& a) { return "ontime.Action('" + a.id + "')"; });

  py::class_<Problem, std::shared_ptr<Problem>>(
      m, "Problem",
      "An effort-allocation problem (SPEC §1): a deadline in steps, abstract actions with their time "
      "distributions, and plan skeletons sharing actions along common prefixes. Immutable.\n\n"
      "Make one with ontime.load_problem(path), Problem.from_dict(d) or Problem.from_json(text).")
      .def_static(
          "from_json",
          [](const std::string& text, const std::string& source) {
            return std::make_shared<Problem>(parse_problem(text, source));
          },
          py::arg("text"), py::arg("source") = "<json>",
          "Reads an instance from JSON text (SPEC §5); `source` names it in InputError messages.")
      .def(
          "to_json", [](const Problem& p) { return problem_to_json(p); },
          "The instance as JSON text (PMF form, sorted keys), readable back by from_json.")
      .def(
          "save",
          [](const Problem& p, const py::object& path) {
            save_problem(p, std::string(py::str(py::module_::import("os").attr("fspath")(path))));
          },
          py::arg("path"), "Writes the instance file atomically (the old file or the whole new one, never a mix).")
      .def_property_readonly("name", &Problem::name)
      .def_property_readonly("description", &Problem::description)
      .def_property_readonly("deadline", &Problem::deadline, "The deadline D in steps.")
      .def_property_readonly("step_seconds", &Problem::step_seconds, "Seconds of one step.")
      .def_property_readonly(
          "actions", [](const Problem& p) { return std::vector<Action>(p.actions().begin(), p.actions().end()); },
          "The actions, in index order (an action index in a Decision or World.step indexes this list).")
      .def_property_readonly(
          "action_ids",
          [](const Problem& p) {
            std::vector<std::string> ids;
            for (const Action& action : p.actions()) ids.push_back(action.id);
            return ids;
          },
          "The action ids, in index order.")
      .def_property_readonly(
          "skeletons",
          [](const Problem& p) {
            std::vector<std::vector<std::string>> out;
            for (int k = 0; k < p.skeleton_count(); ++k) {
              std::vector<std::string>& ids = out.emplace_back();
              for (const int action : p.skeleton(k)) ids.push_back(p.action(action).id);
            }
            return out;
          },
          "The skeletons as lists of action ids.")
      .def_property_readonly("skeleton_count", &Problem::skeleton_count)
      .def("find_action", &Problem::find_action, py::arg("id"), "Index of the action with this id, or -1.")
      .def("__repr__", [](const Problem& p) {
        return "ontime.Problem('" + p.name() + "', deadline=" + std::to_string(p.deadline()) + ", " +
               std::to_string(p.skeleton_count()) + " skeletons, " + std::to_string(p.action_count()) + " actions)";
      });

  m.def(
      "load_problem",
      [](const py::object& path) {
        const std::string file = py::str(py::module_::import("os").attr("fspath")(path));
        const py::gil_scoped_release release;
        return std::make_shared<Problem>(load_problem(file));
      },
      py::arg("path"), "Reads and validates an instance file (SPEC §5). Raises InputError naming the place and rule.");

  m.def(
      "reduce_knapsack",
      [](const py::object& knapsack, const std::optional<std::string>& name) {
        const bool is_file = py::isinstance<py::str>(knapsack) || py::hasattr(knapsack, "__fspath__");
        const std::string source =
            is_file ? std::string(py::str(py::module_::import("os").attr("fspath")(knapsack))) : "<knapsack>";
        const std::string text =
            is_file ? std::string() : std::string(py::str(py::module_::import("json").attr("dumps")(knapsack)));
        const py::gil_scoped_release release;
        const Knapsack parsed = is_file ? load_knapsack(source) : parse_knapsack(text, source);
        const std::string problem_name =
            name ? *name : (is_file ? std::filesystem::path(source).stem().string() : "knapsack-reduction");
        return std::make_shared<Problem>(reduce_knapsack(parsed, problem_name));
      },
      py::arg("knapsack"), py::kw_only(), py::arg("name") = py::none(),
      "The effort-allocation instance of Theorem 1 for a knapsack problem (a file, or a dict {'capacity': W, "
      "'items': [{'weight': w, 'value': v}, ...]}), as `ontime reduce-knapsack` writes it; named after the file "
      "unless `name` is given. Its optimum orders the knapsack's solutions by value (docs/theory.md).");

  m.def(
      "histogram_csv", [](const py::object& problem) { return report::histogram_csv(*to_mdp(problem)->problem); },
      py::arg("problem"),
      "Every action's planning and execution PMF as the CSV `ontime plot` writes beside its picture "
      "(action,distribution,step,probability; 'never' last); python/plot_histograms.py --data CSV draws it.");

  m.def(
      "sample_log",
      [](const py::object& problem, const py::object& path, Number<std::uint64_t, "attempts", 1> attempts, Seed seed,
         std::optional<Number<Steps, "cutoff", 1>> cutoff) {
        const std::shared_ptr<MdpHandle> mdp = to_mdp(problem);
        const std::string file = py::str(py::module_::import("os").attr("fspath")(path));
        LogSamplingOptions options;
        options.attempts_per_action = attempts;
        options.seed = seed;
        options.cutoff_steps = cutoff ? static_cast<Steps>(*cutoff) : 0;
        const py::gil_scoped_release release;
        return write_sampled_planner_log(*mdp->problem, options, file);
      },
      py::arg("problem"), py::arg("path"), py::kw_only(), py::arg("attempts") = 1000, py::arg("seed") = 1,
      py::arg("cutoff") = py::none(),
      "Draws a planner log from the problem's own distributions and writes it to `path` (JSON Lines), as `ontime "
      "sample-log` does: `attempts` per action, attempt i of action a from stream i of stream a of `seed`, cut "
      "off after `cutoff` steps (default: the deadline). Returns the records written.");

  py::class_<StateView>(m, "State",
                        "An MDP state (SPEC §2): CT, and per skeleton l_k (actions refined), PT_k (steps on its "
                        "current action) and ET_k (execution steps of its refined actions, saturated at D + 1).")
      .def_property_readonly(
          "time", [](const StateView& s) { return s.state.time; }, "CT: steps of effort used.")
      .def_property_readonly(
          "refined", [](const StateView& s) { return first(s.state.refined, s.skeletons); }, "l_k for each skeleton.")
      .def_property_readonly(
          "spent", [](const StateView& s) { return first(s.state.spent, s.skeletons); }, "PT_k for each skeleton.")
      .def_property_readonly(
          "execution", [](const StateView& s) { return first(s.state.execution, s.skeletons); },
          "ET_k for each skeleton.")
      .def("__eq__", [](const StateView& a, const StateView& b) { return a.state == b.state; })
      .def("__hash__",
           [](const StateView& s) {
             return py::hash(py::make_tuple(s.state.time, first(s.state.refined, s.skeletons),
                                            first(s.state.spent, s.skeletons), first(s.state.execution, s.skeletons))
                                 .attr("__str__")());
           })
      .def("__repr__", [](const StateView& s) {
        return "ontime.State(time=" + std::to_string(s.state.time) +
               ", refined=" + std::string(py::str(first(s.state.refined, s.skeletons))) +
               ", spent=" + std::string(py::str(first(s.state.spent, s.skeletons))) +
               ", execution=" + std::string(py::str(first(s.state.execution, s.skeletons))) + ")";
      });

  py::class_<MdpHandle, std::shared_ptr<MdpHandle>>(
      m, "Mdp", "The effort-allocation MDP of a problem (SPEC §2), with its precomputed tables.")
      .def(py::init([](std::shared_ptr<Problem> problem) { return std::make_shared<MdpHandle>(std::move(problem)); }),
           py::arg("problem"))
      .def_property_readonly("problem", [](const MdpHandle& h) { return std::const_pointer_cast<Problem>(h.problem); })
      .def_property_readonly("skeleton_count", [](const MdpHandle& h) { return h.mdp.skeleton_count(); })
      .def_property_readonly("deadline", [](const MdpHandle& h) { return h.mdp.deadline(); })
      .def(
          "start",
          [](const MdpHandle& h) {
            return StateView{h.mdp.start(), h.mdp.skeleton_count()};
          },
          "The start state.")
      .def(
          "next_action",
          [](const MdpHandle& h, const StateView& s, Number<int, "skeleton", 0> k) {
            return h.mdp.next_action(s.state, k);
          },
          py::arg("state"), py::arg("skeleton"), "The action skeleton k refines next, or -1 when it is fully refined.")
      .def(
          "useful_choices",
          [](const MdpHandle& h, const StateView& s) {
            std::vector<int> out;
            for (const int choice : h.mdp.useful_choices(s.state)) out.push_back(choice);
            return out;
          },
          py::arg("state"), "The choices worth considering (one per group sharing a next action), ascending.")
      .def(
          "can_succeed",
          [](const MdpHandle& h, const StateView& s, Number<int, "skeleton", 0> k) {
            return h.mdp.can_succeed(s.state, k);
          },
          py::arg("state"), py::arg("skeleton"), "Whether skeleton k can still meet the deadline from this state.");

  // Planner logs and fitting. Records given from Python are read as JSON Lines text by the
  // library's own reader, so they obey, and are reported against, the same rules as a log file.
  m.def(
      "_parse_planner_log",
      [](const std::string& text, const std::string& source) { return attempts_list(parse_planner_log(text, source)); },
      py::arg("text"), py::arg("source"));
  m.def(
      "read_planner_log",
      [](const py::object& path) {
        const std::string file = py::str(py::module_::import("os").attr("fspath")(path));
        std::vector<RefinementAttempt> attempts;
        {
          const py::gil_scoped_release release;
          attempts = load_planner_log(file);
        }
        return attempts_list(attempts);
      },
      py::arg("path"),
      "Reads a planner log (JSON Lines, docs/formats.md) as a list of dicts with the keys action, "
      "planning_seconds, found, execution_seconds (when found) and trial / collision_checks (when recorded).");
  m.def(
      "_save_planner_log",
      [](const std::string& text, const std::string& source, const std::string& path) {
        const std::vector<RefinementAttempt> attempts = parse_planner_log(text, source);
        const py::gil_scoped_release release;
        save_planner_log(attempts, path);
      },
      py::arg("text"), py::arg("source"), py::arg("path"));
  m.def(
      "_fit",
      [](const std::string& log, bool log_is_path, const std::string& skeleton_data, bool skeletons_are_path,
         Number<double, "step", 0.0> step, Number<Steps, "deadline", 1> deadline,
         Number<double, "laplace", 0.0> laplace, const std::string& name, const std::string& description) {
        const std::string log_source = log_is_path ? log : "<records>";
        const std::vector<RefinementAttempt> attempts =
            log_is_path ? load_planner_log(log) : parse_planner_log(log, log_source);
        const SkeletonList skeletons =
            skeletons_are_path ? load_skeleton_file(skeleton_data) : parse_skeleton_file(skeleton_data, "<skeletons>");
        FitOptions options;
        options.step_seconds = step;
        options.deadline = deadline;
        options.laplace = laplace;
        options.name = name;
        options.description = description;
        if (!(step > 0) || !std::isfinite(step)) throw UsageError("step must be a positive number of seconds");
        if (deadline < 1 || deadline > Problem::kMaxDeadline) {
          throw UsageError("deadline must be in [1, " + std::to_string(Problem::kMaxDeadline) + "] steps");
        }
        const py::gil_scoped_release release;
        return std::make_shared<Problem>(fit_problem(attempts, log_source, skeletons, options).problem);
      },
      py::arg("log"), py::arg("log_is_path"), py::arg("skeleton_data"), py::arg("skeletons_are_path"), py::arg("step"),
      py::arg("deadline"), py::arg("laplace"), py::arg("name"), py::arg("description"));

  m.def(
      "allocators", [] { return json_object(report::registry_json(allocator_registry())); },
      "The allocator kinds of the registry with their capabilities and parameters, as `ontime allocators "
      "--json` lists them. Parameters are passed as keyword arguments with '_' for '-' (max_states=...).");
}

}  // namespace ontime::python
