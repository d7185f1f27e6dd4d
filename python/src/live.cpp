// Bindings of live sessions (ontime/session.hpp): deadlines in seconds on a clock, the
// allocator's thinking and the planner's overruns charged, skeletons that arrive and leave.

#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/session.hpp"
#include "ontime/util/error.hpp"

namespace ontime::python {
namespace {

// A live session that owns its problem and allocator (made from the registry by name), on a
// ManualClock given by the caller or on the steady clock.
struct LiveSessionHandle {
  LiveSessionHandle(const Problem& problem, std::string kind, ParameterValues parameter_values, std::uint64_t seed,
                    py::object manual_clock, double decision_share)
      : clock_object(std::move(manual_clock)),
        clock(clock_object.is_none() ? static_cast<const Clock*>(&steady)
                                     : static_cast<const Clock*>(clock_object.cast<ManualClock*>())),
        name(std::move(kind)),
        values(std::move(parameter_values)),
        session(
            problem,
            [name = name, values = values](const Mdp& mdp) { return make_allocator_factory(name, mdp, values)(); },
            seed, clock, LiveOptions{.decision_share = decision_share}),
        current(std::make_shared<const Problem>(session.problem())) {}

  SteadyClock steady;
  py::object clock_object;  // keeps the caller's ManualClock alive
  const Clock* clock;
  std::string name;
  ParameterValues values;
  Session session;
  std::shared_ptr<const Problem> current;  // the skeletons now, for decisions and Python
};

py::dict step_dict(const LiveStep& step, const Problem& problem) {
  py::dict out;
  out["skeleton"] = step.skeleton;
  out["action"] = step.action;
  out["action_id"] = step.action >= 0 && step.action < problem.action_count()
                         ? py::object(py::str(problem.action(step.action).id))
                         : py::object(py::none());
  out["start"] = step.start;
  out["outside_seconds"] = step.outside_seconds;
  out["decision_seconds"] = step.decision_seconds;
  out["planning_seconds"] = step.planning_seconds;
  out["overrun_seconds"] = step.overrun_seconds;
  out["observe_seconds"] = step.observe_seconds;
  out["steps_charged"] = step.steps_charged;
  out["refined"] = step.refined;
  out["execution_seconds"] = step.refined ? py::object(py::float_(step.execution_seconds)) : py::object(py::none());
  return out;
}

}  // namespace

void bind_live(py::module_& m) {
  py::class_<ManualClock>(m, "ManualClock",
                          "A clock that stands still until advanced: a live session's time in tests and simulations.")
      .def(py::init([](Number<double, "start"> start) { return ManualClock(start); }), py::arg("start") = 0.0)
      .def(
          "advance", [](ManualClock& clock, Seconds seconds) { clock.advance(seconds); }, py::arg("seconds"),
          "Moves the clock on by `seconds` (>= 0, finite; UsageError otherwise).")
      .def_property_readonly("now", &ManualClock::now, "Seconds since the clock's origin.")
      .def("__repr__", [](const ManualClock& c) { return "ontime.ManualClock(now=" + std::to_string(c.now()) + ")"; });

  py::class_<LiveSessionHandle>(
      m, "LiveSession",
      "A session on the robot's clock (docs/live.md): the deadline is D * step_seconds seconds after it "
      "began; the allocator's thinking, the planner's overruns and the caller's own time are charged.\n\n"
      "    session = ontime.LiveSession(problem, 'dp-rerun')   # the steady clock\n"
      "    while session.status == ontime.Status.running:\n"
      "        decision = session.choose()\n"
      "        if decision.skeleton < 0: break            # the deadline passed meanwhile\n"
      "        # one slice (session.step_seconds) of planning on decision.action_id ...\n"
      "        if found: session.report_refined_seconds(execution_seconds)\n"
      "        else: session.report_not_yet()\n\n"
      "Skeletons may arrive (add_skeleton) and leave (retire_skeleton) while it runs; the allocator "
      "(`allocator`, a registry name, with its parameters as keyword arguments) is made anew for each set. "
      "`clock`: an ontime.ManualClock, or None for the steady clock. `decision_share`: the share of a slice "
      "an anytime allocator (mcts) thinks per decision.")
      .def(py::init([](const py::object& problem, const std::string& allocator, Seed seed, const py::object& clock,
                       Number<double, "decision_share", 0.0, 1.0> decision_share, const py::kwargs& kwargs) {
             if (!clock.is_none() && !py::isinstance<ManualClock>(clock)) {
               throw UsageError("clock must be an ontime.ManualClock or None (the steady clock)");
             }
             const std::shared_ptr<MdpHandle> mdp = to_mdp(problem);
             return std::make_unique<LiveSessionHandle>(*mdp->problem, allocator, parameter_values(kwargs), seed, clock,
                                                        decision_share);
           }),
           py::arg("problem"), py::arg("allocator"), py::kw_only(), py::arg("seed") = 0, py::arg("clock") = py::none(),
           py::arg("decision_share") = 0.5)
      .def(
          "choose",
          [](LiveSessionHandle& h) {
            const Decision decision = session_call([&] { return h.session.choose(); });
            return DecisionView{decision.skeleton, decision.action, h.current};
          },
          "Brings the state up to the clock, then asks the allocator. A decision with skeleton -1: the session "
          "ended (the deadline passed, or no skeleton can succeed any more).")
      .def(
          "report_not_yet",
          [](LiveSessionHandle& h, const ChainStates& chains) {
            const Observation observation = with_reported_chains(h.session.mdp(), Observation::not_yet(), chains);
            return session_call([&] { return h.session.report(observation); });
          },
          py::kw_only(), py::arg("chains") = py::none(),
          "The planner's call found no motion. With exogenous chains (SPEC §9), `chains` gives their states now "
          "({chain: state}, required then); steps the clock moved on between reports keep the states last "
          "reported. Returns the status.")
      .def(
          "report_refined_seconds",
          [](LiveSessionHandle& h,
             Number<double, "execution_seconds", 0.0, std::numeric_limits<double>::infinity()> seconds,
             const ChainStates& chains) {
            // Checked first (required with chains, refused without), then carried by the report.
            const std::uint16_t joint = with_reported_chains(h.session.mdp(), Observation::not_yet(), chains).chains;
            return session_call([&] {
              return chains ? h.session.report_refined_seconds(seconds, joint)
                            : h.session.report_refined_seconds(seconds);
            });
          },
          py::arg("execution_seconds"), py::kw_only(), py::arg("chains") = py::none(),
          "The call found a motion taking `execution_seconds` to execute (math.inf: it cannot be executed; not "
          "used for an action whose execution depends on a chain, drawn when it starts). With exogenous chains, "
          "`chains` as for report_not_yet; a completed plan is then worth its expected reward from the reported "
          "states (`reward`).")
      .def_property_readonly(
          "chains", [](const LiveSessionHandle& h) { return chain_states(h.session.mdp(), h.session.state().chains); },
          "The exogenous chains' states (SPEC §9) as last reported, {chain: state}; empty without chains.")
      .def(
          "report_backtrack",
          [](LiveSessionHandle& h, const std::string& culprit) {
            const int index = h.current->find_action(culprit);
            if (index < 0) throw UsageError("report_backtrack: no action '" + culprit + "'");
            return session_call([&] { return h.session.report(Observation::backtracked(index)); });
          },
          py::arg("culprit"),
          "The planner's call gave up (SPEC §7) blaming the earlier action `culprit` (its id): its motion and "
          "everything refined after it are discarded. Returns the status.")
      .def(
          "charge_outside",
          [](LiveSessionHandle& h, Seconds seconds) { session_call([&] { h.session.charge_outside(seconds); }); },
          py::arg("seconds"), "Time the clock did not see but the deadline must.")
      .def(
          "add_skeleton",
          [](LiveSessionHandle& h, const std::vector<std::string>& ids, std::vector<Action> new_actions,
             Number<double, "reward", 0.0, 1.0> reward, Number<double, "reward_per_step", 0.0> reward_per_step) {
            if (ids.empty()) throw UsageError("parameter 'action_ids': give at least one action id");
            const double deadline = h.session.problem().deadline();
            if (reward - reward_per_step * deadline < 0) {
              throw UsageError(
                  "parameter 'reward_per_step': the reward falls below 0 before the deadline (reward - "
                  "reward_per_step * deadline < 0)");
            }
            const int added = session_call([&] {
              return h.session.add_skeleton(ids, std::move(new_actions), SkeletonReward{reward, reward_per_step});
            });
            h.current = std::make_shared<const Problem>(h.session.problem());
            return added;
          },
          py::arg("action_ids"), py::arg("new_actions") = std::vector<Action>{}, py::arg("reward") = 1.0,
          py::arg("reward_per_step") = 0.0,
          "A skeleton arrives: its action ids in order, and the actions the problem does not know yet "
          "(ontime.Action objects, e.g. Problem.from_dict(...).actions), with its reward (SPEC §8: worth "
          "reward - reward_per_step * f when its execution ends at step f). Returns its index.")
      .def(
          "retire_skeleton",
          [](LiveSessionHandle& h, Number<int, "skeleton", 0> k) {
            session_call([&] { h.session.retire_skeleton(k); });
            h.current = std::make_shared<const Problem>(h.session.problem());
          },
          py::arg("skeleton"), "Skeleton k leaves; later skeletons move down by one index.")
      .def(
          "revise_distributions",
          [](LiveSessionHandle& h, const py::object& beliefs) {
            const std::shared_ptr<MdpHandle> source = to_mdp(beliefs, "beliefs");
            session_call([&] { h.session.revise_distributions(*source->problem); });
            h.current = std::make_shared<const Problem>(h.session.problem());
          },
          py::arg("beliefs"),
          "Every action takes the distributions of the action of `beliefs` (a Problem or an instance's path) with "
          "its id or its base id (move(A,B) for move(A,B)#2), e.g. OnlineBelief.believed(); the state stays and "
          "the allocator is made anew to plan with them.")
      .def_property_readonly(
          "attempts", [](const LiveSessionHandle& h) { return h.session.attempts(); },
          "What the session saw of each action of `problem`, by action index (ontime.ActionAttempt): the slices "
          "of effort charged to it and whether a motion was found.")
      .def_property_readonly("status", [](const LiveSessionHandle& h) { return h.session.status(); })
      .def_property_readonly(
          "model_status", [](const LiveSessionHandle& h) { return h.session.model_status(); },
          "The same planner calls judged by the model's step clock (running: not decided when the session ended).")
      .def_property_readonly(
          "solution",
          [](const LiveSessionHandle& h) -> py::object {
            if (h.session.solution() < 0) return py::none();
            return py::int_(h.session.solution());
          },
          "The skeleton to execute after success, else None.")
      .def_property_readonly(
          "reward", [](const LiveSessionHandle& h) { return h.session.reward(); },
          "What the episode earned (SPEC §8): after a success the solution's reward at the end of its execution in "
          "steps of the robot's clock (1.0 without rewards), else 0.0.")
      .def_property_readonly("state",
                             [](const LiveSessionHandle& h) {
                               return StateView{h.session.state(), h.session.problem().skeleton_count(), h.current};
                             })
      .def_property_readonly(
          "problem", [](const LiveSessionHandle& h) { return std::const_pointer_cast<Problem>(h.current); },
          "The skeletons now (a copy).")
      .def_property_readonly("steps_used", [](const LiveSessionHandle& h) { return h.session.steps_used(); })
      .def_property_readonly("step_seconds", [](const LiveSessionHandle& h) { return h.session.step_seconds(); })
      .def_property_readonly("deadline_seconds",
                             [](const LiveSessionHandle& h) { return h.session.deadline_seconds(); })
      .def_property_readonly(
          "elapsed_seconds", [](const LiveSessionHandle& h) { return h.session.elapsed_seconds(); },
          "Seconds gone (frozen once the session ended).")
      .def_property_readonly(
          "timeline",
          [](const LiveSessionHandle& h) {
            py::list steps;
            for (const LiveStep& step : h.session.timeline()) steps.append(step_dict(step, *h.current));
            return steps;
          },
          "One dict per step: skeleton, action, action_id, start, outside/decision/planning/overrun/observe seconds, "
          "steps_charged, refined, execution_seconds.")
      .def_property_readonly(
          "totals",
          [](const LiveSessionHandle& h) {
            const LiveTotals totals = h.session.totals();
            py::dict out;
            out["decision"] = totals.decision;
            out["planning"] = totals.planning;
            out["overrun"] = totals.overrun;
            out["outside"] = totals.outside;
            out["elapsed"] = totals.elapsed;
            return out;
          },
          "Seconds charged so far: decision, planning, overrun, outside, elapsed.")
      .def("__repr__", [](const LiveSessionHandle& h) {
        return "ontime.LiveSession(" + h.name + ", " + status_name(h.session.status()) + ", " +
               std::to_string(h.session.elapsed_seconds()) + " s of " + std::to_string(h.session.deadline_seconds()) +
               " s)";
      });
}

}  // namespace ontime::python
