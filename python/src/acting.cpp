// Acting while planning from Python (SPEC §10): ontime.ConcurrentSession, the session whose moves
// are starts and steps, driven by a registry allocator or by the caller.

#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/run/concurrent_session.hpp"

namespace ontime::python {
namespace {

// A concurrent session with what it refers to: its problem, its MDP and its allocator (if any).
struct ConcurrentSessionHandle {
  ConcurrentSessionHandle(std::shared_ptr<const Problem> chosen, const std::optional<std::string>& solver,
                          std::uint64_t seed, const ParameterValues& values)
      : problem(std::move(chosen)), mdp(std::make_unique<ConcurrentMdp>(*problem)) {
    if (solver) {
      allocator = make_concurrent_allocator_factory(*solver, *mdp, values)();
      session = std::make_unique<ConcurrentSession>(*mdp, *allocator, seed);
    } else {
      if (!values.all().empty()) {
        throw UsageError("allocator parameters (" + values.all().begin()->first +
                         ", ...) need a solver: without one the caller decides every move");
      }
      session = std::make_unique<ConcurrentSession>(*mdp, seed);
    }
  }
  std::shared_ptr<const Problem> problem;
  std::unique_ptr<ConcurrentMdp> mdp;
  std::unique_ptr<ConcurrentAllocator> allocator;
  std::unique_ptr<ConcurrentSession> session;
};

// An action named by its id (a str, as Problem.actions and the moves name it), for a message naming
// `parameter`.
int action_index(const Problem& problem, const py::object& action, const char* parameter) {
  if (!py::isinstance<py::str>(action)) {
    throw UsageError(std::string(parameter) + ": an action's id (str) (got " + std::string(py::repr(action)) + ")");
  }
  const std::string id = action.cast<std::string>();
  const int index = problem.find_action(id);
  if (index < 0) throw UsageError(std::string(parameter) + ": no action '" + id + "'");
  return index;
}

py::dict decision_dict(const Problem& problem, const ConcurrentDecision& decision) {
  py::dict out;
  out["start"] = decision.is_start() ? py::object(py::str(problem.action(decision.start).id)) : py::none();
  out["skeleton"] = decision.is_start() || decision.skeleton < 0 ? py::none() : py::object(py::int_(decision.skeleton));
  out["action"] = decision.action < 0 ? py::none() : py::object(py::str(problem.action(decision.action).id));
  return out;
}

}  // namespace

void bind_acting(py::module_& m) {
  py::class_<ConcurrentSessionHandle>(
      m, "ConcurrentSession",
      "A session in which the robot acts while planning (SPEC §10): each move is a start (the robot begins "
      "executing a refined action now; no time passes) or a step (the planner refines one action, or idles, "
      "while the robot executes).\n\n"
      "    session = ontime.ConcurrentSession(problem, 'dp-rerun')\n"
      "    while session.status == ontime.Status.running:\n"
      "        move = session.choose()\n"
      "        if move['start'] is not None: robot.execute(move['start']); continue\n"
      "        # one step of planning on move['action'] (None: the planner idles) ...\n"
      "        if found: session.report_refined(execution_steps)\n"
      "        else: session.report_not_yet()\n\n"
      "Without a solver the caller decides every move (decide()). The session runs on the model's steps; a robot "
      "that finishes an execution sooner reports it (report_execution_finished).")
      .def(py::init([](const py::object& problem, const std::optional<std::string>& solver, Seed seed,
                       const py::kwargs& kwargs) {
             return std::make_unique<ConcurrentSessionHandle>(problem_with_acting(problem, "concurrent"), solver, seed,
                                                              parameter_values(kwargs));
           }),
           py::arg("problem"), py::arg("solver") = py::none(), py::kw_only(), py::arg("seed") = 0,
           "`problem`: a Problem or an instance's path, read acting while planning whatever its own mode. `solver`: "
           "an allocator with a commit rule (`ontime.allocators()`), its parameters as keyword arguments; None: "
           "the caller decides.")
      .def(
          "choose",
          [](ConcurrentSessionHandle& h) {
            return decision_dict(*h.problem, session_call([&] { return h.session->choose(); }));
          },
          "The allocator's next move as {'start': action id or None, 'skeleton': int or None, 'action': action id "
          "or None}: a start is carried out at once (it may end the session); a step awaits its report.")
      .def(
          "decide",
          [](ConcurrentSessionHandle& h, const py::object& start, const py::object& refine) {
            ConcurrentMdp::Move move;
            if (!start.is_none() && !refine.is_none()) throw UsageError("decide: give start or refine, not both");
            if (!start.is_none()) move.start = action_index(*h.problem, start, "start");
            if (!refine.is_none()) {
              if (!py::isinstance<py::int_>(refine) || py::isinstance<py::bool_>(refine)) {
                throw UsageError("refine: a skeleton's index (int) (got " + std::string(py::repr(refine)) + ")");
              }
              // Compared in Python's integers, so that any int is refused without overflowing.
              if (refine.attr("__lt__")(0).cast<bool>() ||
                  refine.attr("__ge__")(h.problem->skeleton_count()).cast<bool>()) {
                throw UsageError("refine: no skeleton " + std::string(py::str(refine)) + " (the problem has " +
                                 std::to_string(h.problem->skeleton_count()) + ")");
              }
              move.refine = refine.cast<int>();
            }
            return decision_dict(*h.problem, session_call([&] { return h.session->decide(move); }));
          },
          py::kw_only(), py::arg("start") = py::none(), py::arg("refine") = py::none(),
          "The caller's move (a session without a solver): start=ACTION (its id) starts it, refine=K spends "
          "the step on skeleton K's next action, neither: the planner idles for a step. Checked as the "
          "allocator's moves are (UsageError naming the rule).")
      .def(
          "report_not_yet",
          [](ConcurrentSessionHandle& h) { return session_call([&] { return h.session->report_not_yet(); }); },
          "The step found no motion (or the planner idled). Returns the status.")
      .def(
          "report_refined",
          [](ConcurrentSessionHandle& h, Number<long long, "execution_steps", 0> execution_steps) {
            const Steps steps = execution_steps >= kNever ? kNever : static_cast<Steps>(execution_steps);
            return session_call([&] { return h.session->report_refined(steps); });
          },
          py::arg("execution_steps"),
          "The step found a motion that takes `execution_steps` to execute (ontime.NEVER: it cannot be). Returns "
          "the status.")
      .def(
          "report_backtrack",
          [](ConcurrentSessionHandle& h, const py::object& culprit) {
            const int index = action_index(*h.problem, culprit, "culprit");
            return session_call([&] { return h.session->report(Observation::backtracked(index)); });
          },
          py::arg("culprit"),
          "The step gave up (SPEC §7) blaming the earlier action `culprit` (its id): its motion and everything "
          "refined after it are discarded (a culprit the robot executed stays, its action blocked). Returns the "
          "status.")
      .def(
          "report_execution_finished",
          [](ConcurrentSessionHandle& h, const py::object& action) {
            const int index = action_index(*h.problem, action, "action");
            return session_call([&] { return h.session->report_execution_finished(index); });
          },
          py::arg("action"),
          "The robot finished executing `action` (its id), possibly sooner than its execution time: it is "
          "idle now. UsageError for an action the session never started. Returns the status.")
      .def_property_readonly("status", [](const ConcurrentSessionHandle& h) { return h.session->status(); })
      .def_property_readonly(
          "solution",
          [](const ConcurrentSessionHandle& h) -> py::object {
            return h.session->solution() < 0 ? py::none() : py::object(py::int_(h.session->solution()));
          },
          "After success, the skeleton whose last action the robot started; else None.")
      .def_property_readonly(
          "reward", [](const ConcurrentSessionHandle& h) { return h.session->reward(); },
          "What the episode earned (SPEC §8): the solution's reward at its finish (1.0 without rewards), else 0.0.")
      .def_property_readonly(
          "finish",
          [](const ConcurrentSessionHandle& h) -> py::object {
            return h.session->finish() < 0 ? py::none() : py::object(py::int_(h.session->finish()));
          },
          "The step at which the last execution ends, after the last start; else None.")
      .def_property_readonly(
          "steps_used", [](const ConcurrentSessionHandle& h) { return h.session->steps_used(); }, "CT: steps used.")
      .def_property_readonly(
          "robot_left", [](const ConcurrentSessionHandle& h) { return ConcurrentMdp::robot_left(h.session->state()); },
          "The steps the robot still needs for the action it executes (0: idle).")
      .def_property_readonly(
          "started",
          [](const ConcurrentSessionHandle& h) {
            std::vector<std::string> ids;
            for (const int action : h.session->started()) ids.push_back(h.problem->action(action).id);
            return ids;
          },
          "The ids of the actions started, in order.")
      .def_property_readonly(
          "live",
          [](const ConcurrentSessionHandle& h) {
            std::vector<bool> live;
            for (int k = 0; k < h.problem->skeleton_count(); ++k) {
              live.push_back(ConcurrentMdp::is_live(h.session->state(), k));
            }
            return live;
          },
          "Per skeleton: whether it is through what the robot executed and can still finish by the deadline.")
      .def_property_readonly(
          "startable",
          [](const ConcurrentSessionHandle& h) {
            std::vector<std::string> ids;
            for (const int action : h.mdp->startable(h.session->state())) ids.push_back(h.problem->action(action).id);
            return ids;
          },
          "The ids of the actions the robot may start now (refined, just after what it executed; idle robot).")
      .def_property_readonly(
          "problem", [](const ConcurrentSessionHandle& h) { return std::const_pointer_cast<Problem>(h.problem); },
          "The problem, acting while planning.");
}

}  // namespace ontime::python
