// Bindings of the run layer: sessions a caller's planner drives, worlds written in Python, and the
// long computations on the library's one episode runner (episodes, evaluation, Table I, studies).

#include <pybind11/operators.h>
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <stdexcept>

#include "bindings.hpp"
#include "ontime/allocators/belief_models.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/learn/online_adaptation.hpp"
#include "ontime/report/report.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/experiments.hpp"
#include "ontime/run/regret.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/run/table.hpp"
#include "ontime/util/error.hpp"

namespace ontime::python {

namespace {

struct SessionHandle {
  SessionHandle(std::shared_ptr<AllocatorHandle> handle, std::uint64_t seed_value, DecisionBudget default_budget)
      : allocator(std::move(handle)),
        session(allocator->mdp->mdp, *allocator->allocator, seed_value),
        budget(std::move(default_budget)) {}
  std::shared_ptr<AllocatorHandle> allocator;
  Session session;
  DecisionBudget budget;
};

// A World implemented in Python (a subclass of ontime.World), called with the GIL held.
class PythonWorld final : public World {
 public:
  PythonWorld(py::object world, int action_count) : world_(std::move(world)), action_count_(action_count) {}
  ~PythonWorld() override {
    const py::gil_scoped_acquire acquire;
    world_ = py::object();
  }
  PythonWorld(const PythonWorld&) = delete;
  PythonWorld& operator=(const PythonWorld&) = delete;

  void begin_episode(std::uint64_t seed) override {
    const py::gil_scoped_acquire acquire;
    world_.attr("begin_episode")(seed);
  }

  Observation step(int action, Steps spent) override {
    const py::gil_scoped_acquire acquire;
    const py::object result = world_.attr("step")(action, spent);
    if (result.is_none()) return Observation::not_yet();
    if (py::isinstance<py::tuple>(result)) {
      const auto pair = result.cast<py::tuple>();
      if (py::len(pair) == 2 && py::isinstance<py::str>(pair[0]) && pair[0].cast<std::string>() == "backtrack") {
        // ("backtrack", culprit action index): the attempt gave up blaming that action (SPEC §7).
        const py::object culprit = pair[1];
        if (PyBool_Check(culprit.ptr()) || !py::hasattr(culprit, "__index__")) {
          throw UsageError("World.step: a backtrack is (\"backtrack\", the index of the action blamed), not " +
                           std::string(py::repr(result)));
        }
        const auto index = py::int_(culprit).cast<long long>();
        if (index < 0 || index >= static_cast<long long>(action_count_)) {
          throw UsageError("World.step: a backtrack blames action " + std::to_string(index) + ", not an action index");
        }
        return Observation::backtracked(static_cast<int>(index));
      }
    }
    if (py::isinstance<py::bool_>(result)) {
      throw UsageError("World.step must return None (not yet) or the execution time in steps, not a bool");
    }
    if (py::isinstance<py::float_>(result) && std::isinf(result.cast<double>()) && result.cast<double>() > 0) {
      return Observation::found(kNever);
    }
    if (!py::hasattr(result, "__index__")) {
      throw UsageError(
          "World.step must return None (not yet) or the execution time in steps (an int, "
          "ontime.NEVER or math.inf), got " +
          std::string(py::str(py::type::of(result).attr("__name__"))));
    }
    const auto steps = py::int_(result).cast<long long>();
    if (steps < 0) throw UsageError("World.step returned a negative execution time (" + std::to_string(steps) + ")");
    return Observation::found(steps >= kNever ? kNever : static_cast<Steps>(steps));
  }

  void collect_statistics(Statistics& statistics) const override {
    const py::gil_scoped_acquire acquire;
    if (!py::hasattr(world_, "statistics")) return;
    const py::object counters = world_.attr("statistics")();
    if (!py::isinstance<py::dict>(counters)) {
      throw UsageError("World.statistics must return a dict of counters (name -> number)");
    }
    for (const auto& [name, value] : py::reinterpret_borrow<py::dict>(counters)) {
      if (PyBool_Check(value.ptr()) || (!py::isinstance<py::int_>(value) && !py::isinstance<py::float_>(value) &&
                                        !py::hasattr(value, "__float__"))) {
        throw UsageError("World.statistics: counter '" + std::string(py::str(name)) + "' is not a number");
      }
      statistics.add(std::string(py::str(name)), py::float_(py::reinterpret_borrow<py::object>(value)).cast<double>());
    }
  }

 private:
  py::object world_;
  int action_count_;
};

// `options` stopped by `stop` and counting its episodes in `progress`.
MonteCarloOptions with_hooks(MonteCarloOptions options, const std::function<bool()>& stop, Progress& progress) {
  progress.total = options.episodes;
  options.stop = stop;
  options.progress = [&progress](std::uint64_t done, std::uint64_t) { progress.done = done; };
  return options;
}

MonteCarloResult run_with_hooks(const Mdp& mdp, const WorldFactory& worlds, const AllocatorFactory& factory,
                                const MonteCarloOptions& options, const std::function<bool()>& stop,
                                Progress& progress) {
  return run_episodes(mdp, worlds, factory, with_hooks(options, stop, progress));
}

}  // namespace

// The observation with the chains' states a caller reported after the step ({chain: state}, by
// name; SPEC §9), which an instance with chains needs and one without refuses.
Observation with_reported_chains(const Mdp& mdp, Observation observation, const ChainStates& reported) {
  const auto chains = mdp.problem().chains();
  if (!reported) {
    if (mdp.has_chains()) {
      throw UsageError("this instance has exogenous chains: report their states after the step (chains={name: state})");
    }
    return observation;
  }
  std::vector<int> states;
  for (const ExogenousChain& chain : chains) {
    const auto found = reported->find(chain.name);
    if (found == reported->end()) throw UsageError("chains: the state of chain '" + chain.name + "' is missing");
    const int state = chain.state_index(found->second);
    if (state < 0) throw UsageError("chains: chain '" + chain.name + "' has no state '" + found->second + "'");
    states.push_back(state);
  }
  for (const auto& [name, state] : *reported) {
    bool known = false;
    for (const ExogenousChain& chain : chains) known = known || chain.name == name;
    if (!known) throw UsageError("chains: no chain named '" + name + "' is declared");
  }
  return observation.with_chains(mdp.joint_chain_state(states));
}

std::map<std::string, std::string> chain_states(const Mdp& mdp, std::uint16_t joint) {
  std::map<std::string, std::string> out;
  const auto chains = mdp.problem().chains();
  for (std::size_t c = 0; c < chains.size(); ++c) {
    out[chains[c].name] = chains[c].states[static_cast<std::size_t>(mdp.chain_state(joint, static_cast<int>(c)))];
  }
  return out;
}

void check_episodes(std::uint64_t episodes) {
  if (episodes == 0) throw UsageError("episodes must be at least 1");
}

std::pair<MonteCarloResult, std::optional<ExactEvaluation>> run_and_evaluate(
    const MdpHandle& mdp, const WorldFactory& worlds, const AllocatorFactory& factory, const MonteCarloOptions& options,
    bool exact, const ParameterValues& values, const py::object& progress) {
  MonteCarloResult result;
  std::optional<ExactEvaluation> exact_result;
  run_interruptibly(
      [&](const std::function<bool()>& stop, Progress& counters) {
        result = run_with_hooks(mdp.mdp, worlds, factory, options, stop, counters);
        if (exact) {
          const auto allocator = factory();
          exact_result = evaluate_exactly(mdp.mdp, *allocator, max_states_of(values), stop);
        }
      },
      progress);
  return {result, exact_result};
}

py::dict monte_carlo_dict(const std::string& solver, const ParameterValues& values, const std::string& instance,
                          const Problem& problem, const MonteCarloResult& result, std::uint64_t seed,
                          const std::optional<ExactEvaluation>& exact) {
  return json_object(report::to_json(report::Evaluation{.solver = solver,
                                                        .parameters = values,
                                                        .instance = instance,
                                                        .problem = &problem,
                                                        .seed = seed,
                                                        .result = result,
                                                        .exact = exact,
                                                        .regret = regret_estimate(result.statistics),
                                                        .timing = true}));
}

namespace {

// evaluate(act='concurrent'): the allocator's concurrent form (SPEC §10) in the same hidden worlds.
py::dict evaluate_concurrent(const py::object& source, const Problem& problem, const std::string& solver,
                             std::uint64_t episodes, std::uint64_t seed, unsigned threads, bool exact, bool regret,
                             const py::object& belief, const py::object& progress, const ParameterValues& values) {
  // With a belief the allocator decides on the belief's model (ConcurrentBeliefModels), as
  // `ontime evaluate --belief` does.
  std::optional<Problem> planned;
  if (!belief.is_none()) planned.emplace(with_distributions_of(problem, *problem_with_acting(belief, {}, "belief")));
  MonteCarloResult result;
  std::optional<ExactEvaluation> exact_result;
  run_interruptibly(
      [&](const std::function<bool()>& stop, Progress& counters) {
        const ConcurrentBeliefModels models(problem, planned ? &*planned : nullptr);
        const ConcurrentMdp& mdp = models.world();
        const ConcurrentAllocatorFactory factory = models.factory(solver, values);
        MonteCarloOptions options;
        options.episodes = episodes;
        options.seed = seed;
        options.threads = threads;
        result = run_monte_carlo(mdp, regret ? with_regret(mdp, factory, max_states_of(values)) : factory,
                                 with_hooks(options, stop, counters));
        if (exact) {
          const auto allocator = factory();
          exact_result = evaluate_exactly(mdp, *allocator, max_states_of(values), stop);
        }
      },
      progress);
  return json_object(report::to_json(report::Evaluation{.solver = solver,
                                                        .parameters = values,
                                                        .instance = instance_label(source, problem),
                                                        .problem = &problem,
                                                        .belief = planned ? instance_label(belief, *planned) : "",
                                                        .seed = seed,
                                                        .result = result,
                                                        .exact = exact_result,
                                                        .regret = regret_estimate(result.statistics),
                                                        .timing = true}));
}

}  // namespace

void bind_run(py::module_& m) {
  py::class_<DecisionView>(m, "Decision", "An allocator's decision: which skeleton, which action to refine now.")
      .def_readonly("skeleton", &DecisionView::skeleton, "The skeleton chosen (0-based).")
      .def_readonly("action", &DecisionView::action,
                    "The index of the action to refine now (into Problem.actions), or -1: the step is spent idle.")
      .def_property_readonly(
          "action_id",
          [](const DecisionView& d) -> py::object {
            if (d.action < 0) return py::none();
            return py::str(d.problem->action(d.action).id);
          },
          "The id of the action to refine now, or None.")
      .def("__repr__", [](const DecisionView& d) {
        return "ontime.Decision(skeleton=" + std::to_string(d.skeleton) + ", action=" + std::to_string(d.action) +
               (d.action >= 0 ? " '" + d.problem->action(d.action).id + "'" : std::string()) + ")";
      });

  py::class_<EndedAttempt>(m, "EndedAttempt",
                           "An attempt of an action that a backtrack ended before the episode did (SPEC §7): after "
                           "`effort` steps, with a motion the backtrack discarded (found), by giving up itself "
                           "(backtracked), or with neither (cut off).")
      .def(py::init([](Number<Steps, "effort", 0> effort, bool found, bool backtracked) {
             if (found && backtracked) {
               throw UsageError("found and backtracked: an attempt ends with a motion or by backtracking, not both");
             }
             return EndedAttempt{effort, found, backtracked};
           }),
           py::arg("effort"), py::arg("found").noconvert() = false, py::arg("backtracked").noconvert() = false)
      .def_readonly("effort", &EndedAttempt::effort)
      .def_readonly("found", &EndedAttempt::found)
      .def_readonly("backtracked", &EndedAttempt::backtracked)
      .def(py::self == py::self)  // NOLINT(misc-redundant-expression)
      .def("__repr__", [](const EndedAttempt& a) {
        return "ontime.EndedAttempt(effort=" + std::to_string(a.effort) + ", found=" + (a.found ? "True" : "False") +
               ", backtracked=" + (a.backtracked ? "True" : "False") + ")";
      });

  py::class_<ActionAttempt>(m, "ActionAttempt",
                            "What a session saw of one action: the steps of effort its current refinement got and "
                            "whether it found a motion, and `ended`, the attempts a backtrack ended before it "
                            "(ontime.EndedAttempt; empty without backtracking). An OnlineBelief learns from it.")
      .def(py::init([](Number<Steps, "effort", 0> effort, bool found, std::vector<EndedAttempt> ended) {
             return ActionAttempt{effort, found, std::move(ended)};
           }),
           py::arg("effort"), py::arg("found").noconvert(), py::arg("ended") = std::vector<EndedAttempt>{})
      .def_readonly("effort", &ActionAttempt::effort)
      .def_readonly("found", &ActionAttempt::found)
      .def_readonly("ended", &ActionAttempt::ended)
      .def(py::self == py::self)  // NOLINT(misc-redundant-expression)
      .def("__repr__", [](const ActionAttempt& a) {
        std::string text =
            "ontime.ActionAttempt(effort=" + std::to_string(a.effort) + ", found=" + (a.found ? "True" : "False");
        if (!a.ended.empty()) text += ", ended=[" + std::to_string(a.ended.size()) + " attempts]";
        return text + ")";
      });

  py::class_<SessionHandle>(
      m, "Session",
      "An online session: the caller's own planner does the work, the allocator decides.\n\n"
      "    session = ontime.Session(ontime.make_allocator(problem, 'dp-rerun'))\n"
      "    while session.status == ontime.Status.running:\n"
      "        decision = session.choose()\n"
      "        # one step of planning effort on decision.action_id ...\n"
      "        if found: session.report_refined(execution_steps)\n"
      "        else: session.report_not_yet()\n"
      "    if session.status == ontime.Status.success: execute(session.solution)\n\n"
      "`iterations` / `seconds` set the per-decision budget of an anytime allocator (mcts) for every decision; "
      "choose() may override it for one. The allocator must not serve another session at the same time.")
      .def(py::init([](const Required<AllocatorHandle, "allocator">& allocator, Seed seed,
                       std::optional<Iterations> iterations, std::optional<Seconds> seconds) {
             return std::make_unique<SessionHandle>(allocator.pointer, seed, budget_of(iterations, seconds));
           }),
           py::arg("allocator"), py::arg("seed") = 0, py::kw_only(), py::arg("iterations") = py::none(),
           py::arg("seconds") = py::none())
      .def(
          "choose",
          [](SessionHandle& h, std::optional<Iterations> iterations, std::optional<Seconds> seconds) {
            const DecisionBudget budget = iterations || seconds ? budget_of(iterations, seconds) : h.budget;
            const int skeleton = session_call([&] { return h.session.choose(budget).skeleton; });
            return DecisionView{skeleton, h.session.mdp().next_action(h.session.state(), skeleton),
                                h.allocator->mdp->problem};
          },
          py::kw_only(), py::arg("iterations") = py::none(), py::arg("seconds") = py::none(),
          "Asks the allocator for the next step, within the session's budget, or within `iterations` and/or "
          "`seconds` of search for this decision only.")
      .def(
          "report_not_yet",
          [](SessionHandle& h, const ChainStates& chains) {
            const Observation observation = with_reported_chains(h.session.mdp(), Observation::not_yet(), chains);
            return session_call([&] { return h.session.report(observation); });
          },
          py::kw_only(), py::arg("chains") = py::none(),
          "The step just decided found no motion. With exogenous chains (SPEC §9), `chains` gives their states "
          "after the step ({chain: state}). Returns the status.")
      .def(
          "report_refined",
          [](SessionHandle& h, Number<std::int64_t, "execution_steps", 0> execution_steps, const ChainStates& chains) {
            const Steps steps = execution_steps >= kNever ? kNever : static_cast<Steps>(execution_steps);
            const Observation observation = with_reported_chains(h.session.mdp(), Observation::found(steps), chains);
            return session_call([&] { return h.session.report(observation); });
          },
          py::arg("execution_steps"), py::kw_only(), py::arg("chains") = py::none(),
          "The step just decided found a motion that takes `execution_steps` to execute (ontime.NEVER: it "
          "cannot be executed; ignored for an action whose execution depends on a chain, drawn when it starts). "
          "With exogenous chains, `chains` as for report_not_yet. Returns the status.")
      .def_property_readonly(
          "chains", [](const SessionHandle& h) { return chain_states(h.session.mdp(), h.session.state().chains); },
          "The exogenous chains' states (SPEC §9), {chain: state}; empty without chains.")
      .def(
          "report_backtrack",
          [](SessionHandle& h, const std::string& culprit) {
            const int index = h.allocator->mdp->problem->find_action(culprit);
            if (index < 0) throw UsageError("report_backtrack: no action '" + culprit + "'");
            return session_call([&] { return h.session.report(Observation::backtracked(index)); });
          },
          py::arg("culprit"),
          "The step just decided gave up (SPEC §7) blaming the earlier action `culprit` (its id): its motion and "
          "everything refined after it are discarded. Returns the status.")
      .def_property_readonly("status", [](const SessionHandle& h) { return h.session.status(); })
      .def_property_readonly(
          "state",
          [](const SessionHandle& h) {
            return StateView{h.session.state(), h.session.mdp().skeleton_count(), h.allocator->mdp->problem};
          })
      .def_property_readonly(
          "solution",
          [](const SessionHandle& h) -> py::object {
            if (h.session.solution() < 0) return py::none();
            return py::int_(h.session.solution());
          },
          "The skeleton to execute after success, else None.")
      .def_property_readonly(
          "reward", [](const SessionHandle& h) { return h.session.reward(); },
          "What the episode earned (SPEC §8): after a success the solution's reward at its finish (1.0 without "
          "rewards), else 0.0.")
      .def_property_readonly(
          "steps_used", [](const SessionHandle& h) { return h.session.steps_used(); }, "Steps of effort spent (CT).")
      .def_property_readonly(
          "problem", [](const SessionHandle& h) { return std::const_pointer_cast<Problem>(h.allocator->mdp->problem); },
          "The session's problem.")
      .def_property_readonly(
          "attempts", [](const SessionHandle& h) { return h.session.attempts(); },
          "What the session saw of each action of `problem`, by action index (ontime.ActionAttempt): "
          "OnlineBelief.observe(session.problem, session.attempts) learns from it.")
      .def("__repr__", [](const SessionHandle& h) {
        return std::string("ontime.Session(") + h.allocator->name + ", " + status_name(h.session.status()) +
               ", steps used " + std::to_string(h.session.steps_used()) + ")";
      });

  m.def(
      "run_episodes",
      [](const py::object& problem, const py::object& world, const py::object& allocator, Episodes episodes, Seed seed,
         Threads threads, std::optional<Iterations> iterations, std::optional<Seconds> seconds,
         const py::object& progress, const py::kwargs& kwargs) {
        check_episodes(episodes);
        check_callable(progress, "progress");
        const std::shared_ptr<MdpHandle> mdp = to_mdp(problem);
        std::string solver;
        ParameterValues values;
        if (py::isinstance<AllocatorHandle>(allocator)) {
          const auto& handle = allocator.cast<const AllocatorHandle&>();
          if (handle.mdp->problem != mdp->problem && handle.mdp->problem->name() != mdp->problem->name()) {
            throw UsageError("the allocator was made for another problem ('" + handle.mdp->problem->name() + "')");
          }
          if (kwargs.size() > 0) throw UsageError("give parameters to make_allocator, not with an Allocator");
          solver = handle.name;
          values = handle.values;
        } else if (py::isinstance<py::str>(allocator)) {
          solver = allocator.cast<std::string>();
          values = parameter_values(kwargs);
        } else {
          throw UsageError("parameter 'allocator': must be an ontime.Allocator or the name of an allocator (got " +
                           (allocator.is_none()
                                ? std::string("None")
                                : "a " + std::string(py::str(py::type::of(allocator).attr("__name__")))) +
                           ")");
        }
        // A World object, or a callable (a World's class among them) that makes one per thread.
        const bool instance = !py::isinstance<py::type>(world) && py::hasattr(world, "step");
        if (instance && threads != 1) {
          throw UsageError(
              "one World object runs on one thread: give a factory (e.g. the World's class) for threads != 1");
        }
        if (!instance && PyCallable_Check(world.ptr()) == 0) {
          throw UsageError("parameter 'world': must be an ontime.World or a callable that makes one (got " +
                           (world.is_none() ? std::string("None")
                                            : "a " + std::string(py::str(py::type::of(world).attr("__name__")))) +
                           ")");
        }
        const AllocatorFactory factory = [&] {
          const py::gil_scoped_release release;
          return make_allocator_factory(solver, mdp->mdp, values);
        }();
        const int action_count = mdp->problem->action_count();
        const WorldFactory worlds = [world, instance, action_count]() -> std::unique_ptr<World> {
          const py::gil_scoped_acquire acquire;
          py::object made = instance ? world : world();
          if (!py::hasattr(made, "step") || !py::hasattr(made, "begin_episode")) {
            throw UsageError("the world factory must return an ontime.World (begin_episode and step)");
          }
          return std::make_unique<PythonWorld>(std::move(made), action_count);
        };
        MonteCarloOptions options;
        options.episodes = episodes;
        options.seed = seed;
        options.threads = threads;
        options.decision_budget = budget_of(iterations, seconds);
        MonteCarloResult result;
        run_interruptibly(
            [&](const std::function<bool()>& stop, Progress& counters) {
              result = run_with_hooks(mdp->mdp, worlds, factory, options, stop, counters);
            },
            progress);
        py::dict out =
            monte_carlo_dict(solver, values, instance_label(problem, *mdp->problem), *mdp->problem, result, seed);
        out["world_statistics"] = statistics_dict(result.world_statistics);
        return out;
      },
      py::arg("problem"), py::arg("world"), py::arg("allocator"), py::kw_only(), py::arg("episodes") = 1000,
      py::arg("seed") = 1, py::arg("threads") = 1, py::arg("iterations") = py::none(), py::arg("seconds") = py::none(),
      py::arg("progress") = py::none(),
      "Episodes in which an allocator (an Allocator, or a registry name with its parameters as keyword "
      "arguments) decides and `world` answers: an ontime.World, or a callable making one per thread. The "
      "library's episode runner, seeded as the command line seeds it: episode e begins the world with "
      "stream_seed(seed, e). Returns the command line's result fields plus the allocators' `statistics` and "
      "the worlds' `world_statistics`. `progress(done, total)` is called now and then; Ctrl-C stops the run "
      "(KeyboardInterrupt).");

  m.def(
      "evaluate",
      [](const py::object& problem, const std::string& solver, Episodes episodes, Seed seed, Threads threads,
         bool exact, bool regret, const py::object& belief, const py::object& progress,
         const std::optional<std::string>& act, const py::kwargs& kwargs) {
        check_episodes(episodes);
        check_callable(progress, "progress");
        const std::shared_ptr<const Problem> chosen = problem_with_acting(problem, act);
        if (chosen->acting() == Acting::concurrent) {
          return evaluate_concurrent(problem, *chosen, solver, episodes, seed, threads, exact, regret, belief, progress,
                                     parameter_values(kwargs));
        }
        const std::shared_ptr<MdpHandle> mdp = to_mdp(problem);
        // The allocator's own instance: the problem's skeletons with the belief's distributions.
        std::shared_ptr<MdpHandle> planned = mdp;
        if (!belief.is_none()) {
          planned = std::make_shared<MdpHandle>(std::make_shared<const Problem>(
              with_distributions_of(*mdp->problem, *problem_with_acting(belief, {}, "belief"))));
        }
        const ParameterValues values = parameter_values(kwargs);
        std::optional<AllocatorFactory> factory;
        {
          const py::gil_scoped_release release;
          factory = make_allocator_factory(solver, planned->mdp, values);
          if (regret) factory = with_regret(mdp->mdp, *factory, max_states_of(values));
        }
        MonteCarloOptions options;
        options.episodes = episodes;
        options.seed = seed;
        options.threads = threads;
        const auto [result, exact_result] =
            run_and_evaluate(*mdp, hidden_worlds(*mdp->problem), *factory, options, exact, values, progress);
        py::dict out = monte_carlo_dict(solver, values, instance_label(problem, *mdp->problem), *mdp->problem, result,
                                        seed, exact_result);
        if (!belief.is_none()) out["belief"] = instance_label(belief, *planned->problem);
        return out;
      },
      py::arg("problem"), py::arg("solver"), py::kw_only(), py::arg("episodes") = 10'000, py::arg("seed") = 1,
      py::arg("threads") = 0, py::arg("exact").noconvert() = false, py::arg("regret").noconvert() = false,
      py::arg("belief") = py::none(), py::arg("progress") = py::none(), py::arg("act") = py::none(),
      "Success rate of an allocator over simulated episodes (hidden sampled worlds), as `ontime evaluate "
      "--json` reports it: the same fields and, for the same seed, the same counts whatever `threads`. "
      "exact=True adds the exact success probability (stationary allocators); regret=True the estimate of "
      "V* - V from every decision's exact loss (`ontime evaluate --regret`: 'regret' with optimum, mean, "
      "ci95, episodes). `belief` (an instance, its "
      "path or a Problem): the allocator plans with its distributions for the problem's actions (matched by "
      "id) while the episodes and the exact value are drawn from `problem` (`ontime evaluate --belief`). "
      "act='concurrent' (or a problem whose acting is concurrent): the robot acts while planning (SPEC §10), "
      "the allocator by its commit rule (`ontime evaluate --act`), regret=True by the concurrent optimum's "
      "losses; with a belief, the allocator decides on the belief's model. "
      "Parameters of the allocator as keyword arguments. The GIL is released; Ctrl-C stops it "
      "(KeyboardInterrupt).");

  m.def(
      "adapt",
      [](const py::object& problem, const py::object& belief, const std::string& solver,
         Number<double, "strength", 1e-9, 1e9> strength, Number<std::uint64_t, "episodes", 1, 100'000> episodes,
         Number<std::uint64_t, "sequences", 1, 10'000'000> sequences, Seed seed, Threads threads, bool exact,
         const py::kwargs& kwargs) {
        const std::shared_ptr<MdpHandle> truth = to_mdp(problem);
        const std::shared_ptr<MdpHandle> prior = to_mdp(belief, "belief");
        AdaptationOptions options;
        options.solver = solver;
        options.parameters = parameter_values(kwargs);
        options.strength = strength;
        options.episodes = episodes;
        options.sequences = sequences;
        options.seed = seed;
        options.threads = threads;
        options.exact = exact;
        options.max_states = max_states_of(options.parameters);
        AdaptationResult result;
        {
          const py::gil_scoped_release release;
          result = run_adaptation(*truth->problem, *prior->problem, options);
        }
        py::list rates;
        for (const std::uint64_t s : result.successes) {
          rates.append(static_cast<double>(s) / static_cast<double>(result.sequences));
        }
        py::dict out;
        out["instance"] = instance_label(problem, *truth->problem);
        out["belief"] = instance_label(belief, *prior->problem);
        out["solver"] = solver;
        out["strength"] = options.strength;
        out["episodes"] = options.episodes;
        out["sequences"] = options.sequences;
        out["seed"] = options.seed;
        out["successes"] = result.successes;
        out["success_rate"] = rates;
        if (exact) out["exact_success_probability"] = result.exact;
        return out;
      },
      py::arg("problem"), py::arg("belief"), py::arg("solver") = "dp-rerun", py::kw_only(),
      py::arg("strength") = AdaptationOptions{}.strength, py::arg("episodes") = AdaptationOptions{}.episodes,
      py::arg("sequences") = AdaptationOptions{}.sequences, py::arg("seed") = 1, py::arg("threads") = 0,
      py::arg("exact").noconvert() = true,
      "`ontime adapt`: `sequences` independent runs of `episodes` episodes in `problem` (the truth), the "
      "allocator planning with `belief` (the prior) updated after every episode by the attempts made in it; "
      "per episode the successes and the exact success probability of its plan in the truth, as the "
      "command's --json fields. Allocator parameters as keyword arguments.");

  m.def(
      "table",
      [](const py::sequence& instances, const std::optional<std::vector<std::string>>& solvers, bool exact,
         Episodes episodes, Seed seed, Threads threads, const std::string& format, const py::object& progress,
         const py::kwargs& kwargs) {
        check_episodes(episodes);
        check_callable(progress, "progress");
        if (py::isinstance<py::str>(instances)) {
          throw UsageError("parameter 'instances': must be a list of instances (files or Problems), not a str");
        }
        if (format != "json" && format != "markdown") {
          throw UsageError("format must be 'json' or 'markdown' (got '" + format + "')");
        }
        if (py::len(instances) == 0) throw UsageError("parameter 'instances': give at least one instance");
        TableOptions options;
        if (solvers) {
          if (solvers->empty()) throw UsageError("parameter 'solvers': give at least one allocator");
          options.solvers = *solvers;
        }
        options.exact = exact;
        options.episodes = episodes;
        options.seed = seed;
        options.threads = threads;
        // A parameter given as a list holds one value per instance (a ppo policy for each);
        // given once, it applies to every row.
        const auto count = static_cast<std::size_t>(py::len(instances));
        std::vector<TableInstance> rows;
        for (std::size_t i = 0; i < count; ++i) {
          const py::object source = instances[i];
          py::kwargs row_parameters;
          for (const auto& [key, value] : kwargs) {
            if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
              const auto values = py::reinterpret_borrow<py::sequence>(value);
              if (static_cast<std::size_t>(py::len(values)) != count) {
                throw UsageError("parameter '" + std::string(py::str(key)) + "': " + std::to_string(py::len(values)) +
                                 " values for " + std::to_string(count) + " instances (give one, or one per instance)");
              }
              row_parameters[key] = values[i];
            } else {
              row_parameters[key] = value;
            }
          }
          // Read as a problem: one acting while planning (SPEC §10) makes a row of that mode.
          const std::shared_ptr<const Problem> problem = problem_with_acting(source, std::nullopt, "instances");
          const std::string label = instance_label(source, *problem);
          const bool is_file = py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__");
          const std::string row_label =
              (is_file ? py::str(py::module_::import("pathlib").attr("Path")(source).attr("stem")).cast<std::string>()
                       : label) +
              (problem->acting() == Acting::concurrent ? " (concurrent)" : "");
          rows.push_back({*problem, label, row_label, parameter_values(row_parameters)});
        }
        const ParameterSpelling spelling = python_spelling();
        check_table_request(rows, options, spelling);
        Table table;
        run_interruptibly(
            [&](const std::function<bool()>& stop, Progress& counters) {
              options.stop = stop;
              options.progress = [&counters](std::uint64_t done, std::uint64_t total) {
                counters.total = total;
                counters.done = done;
              };
              table = measure_table(rows, options);
            },
            progress);
        if (format == "markdown") return py::object(py::str(report::to_markdown(table, spelling)));
        return json_object(report::to_json(table));
      },
      py::arg("instances"), py::kw_only(), py::arg("solvers") = py::none(), py::arg("exact").noconvert() = false,
      py::arg("episodes") = 10'000, py::arg("seed") = 1, py::arg("threads") = 0, py::arg("format") = "json",
      py::arg("progress") = py::none(),
      "Table I's layout, as `ontime table` computes it: one row per instance (a file or a Problem), one column "
      "per allocator (default: every one that needs nothing beyond the instance), sampled success ± 95% and, "
      "with exact=True, exact values and the exact optimum (or its certified interval). Parameters as keyword "
      "arguments; a list gives one value per instance (policy=[...]). A problem acting while planning "
      "(Problem.with_acting('concurrent'); SPEC §10) is a row of that mode, labelled 'NAME (concurrent)', as "
      "`ontime table --act`. format='json' returns the dict of `ontime table --json`, 'markdown' the table it "
      "prints. The GIL is released; Ctrl-C stops it.");

  m.def(
      "study",
      [](const std::string& kind_name, const py::sequence& instances, Episodes episodes, Seed seed, Threads threads,
         const std::optional<std::string>& searcher, const std::optional<std::string>& reference,
         const std::optional<std::vector<double>>& log10_multipliers, const py::object& progress,
         const py::kwargs& kwargs) {
        check_callable(progress, "progress");
        if (py::isinstance<py::str>(instances)) {
          throw UsageError("parameter 'instances': must be a list of instances (files or Problems), not a str");
        }
        if (py::len(instances) == 0) throw UsageError("parameter 'instances': give at least one instance");
        const StudyKind kind = study_kind(kind_name);
        StudySettings settings;
        settings.episodes = episodes;
        settings.seed = seed;
        settings.threads = threads;
        if (searcher) settings.searcher = *searcher;
        if (reference) settings.reference = *reference;
        settings.parameters = parameter_values(kwargs);
        std::vector<double> multipliers{0, 0.5, 1, 1.5, 2, 2.5, 3, 3.5, 4, 4.5, 5};
        if (log10_multipliers) {
          if (kind != StudyKind::anytime) throw UsageError("log10_multipliers is for the anytime study");
          for (const double exponent : *log10_multipliers) {
            if (!(exponent >= -3 && exponent <= 9)) {
              throw UsageError("parameter 'log10_multipliers': every value must lie within [-3, 9] (got " +
                               std::string(py::str(py::float_(exponent))) + ")");
            }
          }
          multipliers = *log10_multipliers;
        }
        if (kind != StudyKind::anytime) multipliers.clear();
        std::vector<StudyInstance> rows;
        // Each item held while it is used: a numpy array's items are new objects.
        for (std::size_t i = 0; i < static_cast<std::size_t>(py::len(instances)); ++i) {
          const py::object object = instances[i];
          // Read as a problem (not an Mdp): one acting while planning is studied in that mode.
          const std::shared_ptr<const Problem> problem = problem_with_acting(object, std::nullopt, "instances");
          const std::string label = instance_label(object, *problem);
          const bool is_file = py::isinstance<py::str>(object) || py::hasattr(object, "__fspath__");
          rows.push_back({*problem, label, is_file ? std::filesystem::path(label).stem().string() : label});
        }
        check_study_request(kind, rows, settings, python_spelling());
        StudyRows result;
        run_interruptibly(
            [&](const std::function<bool()>& stop, Progress& counters) {
              settings.progress = [&counters, &stop](std::uint64_t done, std::uint64_t total) {
                if (stop()) throw Cancelled("the study stopped at the caller's request");
                counters.total = total;
                counters.done = done;
              };
              result = run_study(kind, rows, settings, multipliers);
            },
            progress);
        return report::study_csv(result, settings);
      },
      py::arg("kind"), py::arg("instances"), py::kw_only(), py::arg("episodes") = 1'000, py::arg("seed") = 1,
      py::arg("threads") = 0, py::arg("searcher") = py::none(), py::arg("reference") = py::none(),
      py::arg("log10_multipliers") = py::none(), py::arg("progress") = py::none(),
      "A computation-time study of the paper's Figs. 4-6, as `ontime study KIND` runs it: 'compute-time', "
      "'equal-time' or 'anytime' (the searcher, mcts, against the reference, dp-rerun, by default), over the "
      "instances (files or Problems; one acting while planning, Problem.with_acting('concurrent'), is studied in "
      "that mode, as `ontime study --act concurrent`). Returns the CSV the command line writes "
      "(python/plot_study.py draws it). "
      "Times are wall-clock: the success counts of iteration budgets repeat for a seed, those of time budgets do "
      "not. Parameters as keyword arguments. The GIL is released; Ctrl-C stops it.");
}

}  // namespace ontime::python
