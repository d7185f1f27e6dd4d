// Bindings of the model layer: distributions, actions, problems and their instance files, and
// planner logs (read, parsed and written by the library's own readers and writer).

#include <pybind11/numpy.h>
#include <pybind11/operators.h>
#include <pybind11/stl.h>

#include <cmath>
#include <sstream>

#include "bindings.hpp"
#include "ontime/model/exogenous_chain.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/util/error.hpp"

namespace ontime::python {

namespace {

// A distribution made by `make` from the probabilities of a one-dimensional array; UsageError
// naming `parameter` for another array or a bad table.
template <class Make>
Distribution distribution_of(const py::array_t<double, py::array::c_style | py::array::forcecast>& values,
                             const char* parameter, Make make) {
  const std::string name = "parameter '" + std::string(parameter) + "': ";
  if (values.ndim() != 1) throw UsageError(name + "must be a one-dimensional array of probabilities");
  try {
    return make(std::vector<double>(values.data(), values.data() + values.size()));
  } catch (const UsageError& error) {
    throw UsageError(name + error.what());
  }
}

py::object step_or_none(Steps step) { return step == kNever ? py::none() : py::object(py::int_(step)); }

py::dict attempt_dict(const RefinementAttempt& attempt) {
  py::dict out;
  out["action"] = attempt.action;
  out["planning_seconds"] = attempt.planning_seconds;
  out["found"] = attempt.found;
  if (attempt.found) out["execution_seconds"] = attempt.execution_seconds;
  if (attempt.trial) out["trial"] = *attempt.trial;
  if (attempt.collision_checks) out["collision_checks"] = *attempt.collision_checks;
  if (attempt.world) out["world"] = *attempt.world;
  if (!attempt.features.empty()) out["features"] = py::cast(attempt.features);
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
            return distribution_of(masses, "masses",
                                   [](std::vector<double> p) { return Distribution::from_pmf(std::move(p)); });
          },
          py::arg("masses"), "From probabilities: masses[t] = P(T = t). Raises UsageError for a bad table.")
      .def_static(
          "from_cdf",
          [](const py::array_t<double, py::array::c_style | py::array::forcecast>& cumulative) {
            return distribution_of(cumulative, "cumulative",
                                   [](const std::vector<double>& c) { return Distribution::from_cdf(c); });
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
      .def(
          "hazard", [](const Distribution& d, Number<Steps, "spent", 0> spent) { return d.hazard(spent); },
          py::arg("spent"), "P(T = spent + 1 | T > spent): the chance that one more step finishes.")
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
      .def_readonly("backtrack", &Action::backtrack,
                    "Backtracking (SPEC §7): the steps after which an attempt gives up (all 'never': it does not).")
      .def_property_readonly(
          "culprits",
          [](const Action& a) {
            py::dict out;
            for (const Culprit& culprit : a.culprits) out[py::str(culprit.id)] = culprit.probability;
            return out;
          },
          "Backtracking: the earlier actions an attempt that gives up blames, with their probabilities.")
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
          "save", [](const Problem& p, const py::object& path) { save_problem(p, path_argument(path, "path")); },
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
      .def_property_readonly(
          "rewards",
          [](const Problem& p) {
            py::list out;
            for (const SkeletonReward& reward : p.rewards()) {
              py::dict entry;
              entry["value"] = reward.value;
              entry["per_step"] = reward.per_step;
              out.append(entry);
            }
            return out;
          },
          "Each skeleton's reward (SPEC §8) as {'value': v, 'per_step': c}: worth v - c * f when its execution "
          "ends at step f. Every skeleton {'value': 1.0, 'per_step': 0.0} when the instance declares none.")
      .def_property_readonly("has_rewards", &Problem::has_rewards,
                             "Whether some skeleton's reward is not 1 at every finish (the objective is then the "
                             "expected reward, else the success probability).")
      .def_property_readonly("skeleton_count", &Problem::skeleton_count)
      .def_property_readonly(
          "acting", [](const Problem& p) { return std::string(acting_name(p.acting())); },
          "When the robot may execute refined actions (SPEC §10): 'plan-first' (the instance's default) or "
          "'concurrent' (it executes refined actions while the rest is planned).")
      .def(
          "with_acting",
          [](const Problem& p, const py::object& acting) {
            const std::optional<Acting> mode =
                py::isinstance<py::str>(acting) ? parse_acting(acting.cast<std::string>()) : std::nullopt;
            if (!mode) {
              throw UsageError("acting must be 'plan-first' or 'concurrent' (got " + std::string(py::repr(acting)) +
                               ")");
            }
            return std::make_shared<Problem>(p.with_acting(*mode));
          },
          py::arg("acting"), "This problem with another acting mode ('plan-first' or 'concurrent'), the rest kept.")
      .def("find_action", &Problem::find_action, py::arg("id"), "Index of the action with this id, or -1.")
      .def("__repr__", [](const Problem& p) {
        return "ontime.Problem('" + p.name() + "', deadline=" + std::to_string(p.deadline()) + ", " +
               std::to_string(p.skeleton_count()) + " skeletons, " + std::to_string(p.action_count()) + " actions)";
      });

  m.def(
      "load_problem",
      [](const py::object& path) {
        const std::string file = path_argument(path, "path");
        const py::gil_scoped_release release;
        return std::make_shared<Problem>(load_problem(file));
      },
      py::arg("path"), "Reads and validates an instance file (SPEC §5). Raises InputError naming the place and rule.");

  // Planner logs and fitting. Records given from Python are read as JSON Lines text by the
  // library's own reader, so they obey, and are reported against, the same rules as a log file.
  m.def(
      "_parse_planner_log",
      [](const std::string& text, const std::string& source) { return attempts_list(parse_planner_log(text, source)); },
      py::arg("text"), py::arg("source"));

  m.def(
      "read_planner_log",
      [](const py::object& path) {
        const std::string file = path_argument(path, "path");
        std::vector<RefinementAttempt> attempts;
        {
          const py::gil_scoped_release release;
          attempts = load_planner_log(file);
        }
        return attempts_list(attempts);
      },
      py::arg("path"),
      "Reads a planner log (JSON Lines, docs/formats.md) as a list of dicts with the keys action, "
      "planning_seconds, found, execution_seconds (when found) and trial / collision_checks / world / features "
      "(when recorded).");

  m.def(
      "_save_planner_log",
      [](const std::string& text, const std::string& source, const py::object& path) {
        const std::string file = path_argument(path, "path");
        const std::vector<RefinementAttempt> attempts = parse_planner_log(text, source);
        const py::gil_scoped_release release;
        save_planner_log(attempts, file);
      },
      py::arg("text"), py::arg("source"), py::arg("path"));

  py::class_<ExogenousChain>(m, "ExogenousChain",
                             "An exogenous process (docs/learning.md, \"Exogenous chains\"): a finite Markov chain "
                             "that advances one step per time step whatever the robot does. Made by "
                             "ontime.fit_chain or ontime.load_chain.")
      .def_readonly("name", &ExogenousChain::name)
      .def_readonly("states", &ExogenousChain::states)
      .def_property_readonly(
          "start", [](const ExogenousChain& chain) { return chain.states.at(static_cast<std::size_t>(chain.start)); })
      .def_property_readonly(
          "transitions",
          [](const ExogenousChain& chain) {
            const auto n = static_cast<py::ssize_t>(chain.states.size());
            py::array_t<double> matrix({n, n});
            auto view = matrix.mutable_unchecked<2>();
            for (py::ssize_t i = 0; i < n; ++i) {
              for (py::ssize_t j = 0; j < n; ++j) {
                view(i, j) = chain.transitions[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
              }
            }
            return matrix;
          },
          "The transition matrix (numpy, a copy): row i is the distribution of the next state in state i.")
      .def(
          "distribution",
          [](const ExogenousChain& chain, Number<std::int64_t, "steps", 0> steps,
             const std::optional<std::string>& from) {
            int index = chain.start;
            if (from) {
              index = chain.state_index(*from);
              if (index < 0) throw UsageError("chain '" + chain.name + "' has no state '" + *from + "'");
            }
            // Released and stopped by Ctrl-C: a distribution far ahead takes as many steps.
            std::vector<double> distribution;
            run_interruptibly([&](const std::function<bool()>& stop,
                                  Progress&) { distribution = chain_distribution(chain, index, steps, stop); },
                              py::none());
            return py::array_t<double>(static_cast<py::ssize_t>(distribution.size()), distribution.data());
          },
          py::arg("steps"), py::arg("from_state") = py::none(),
          "The distribution of the state `steps` steps after the chain is in `from_state` (default: its start), "
          "over `states` (numpy).")
      .def("to_json", &chain_to_json, "The chain file's text.")
      .def(
          "save",
          [](const ExogenousChain& chain, const py::object& path) { save_chain(chain, path_argument(path, "path")); },
          py::arg("path"), "Writes the chain file (atomically).");

  m.def(
      "load_chain", [](const py::object& path) { return load_chain(path_argument(path, "path")); }, py::arg("path"),
      "Reads a chain file (`ontime fit-chain`'s output); InputError naming the place and the rule.");
}

}  // namespace ontime::python
