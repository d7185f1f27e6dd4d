// Bindings of the mdp layer: the MDP of a problem (transitions, choices, liveness), its states and
// the status of an episode.

#include "ontime/mdp/mdp.hpp"

#include <pybind11/operators.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <string>

#include "bindings.hpp"
#include "ontime/mdp/state.hpp"
#include "ontime/util/error.hpp"

namespace ontime::python {

namespace {

template <class Array>
py::list first(const Array& values, int count) {
  py::list out;
  for (int k = 0; k < count; ++k) out.append(values[static_cast<std::size_t>(k)]);
  return out;
}

// UsageError unless `k` is a skeleton of `mdp`.
void check_skeleton(const Mdp& mdp, int k) {
  if (k >= mdp.skeleton_count()) {
    throw UsageError("parameter 'skeleton': must be a whole number from 0 to " +
                     std::to_string(mdp.skeleton_count() - 1) + " (got " + std::to_string(k) + ")");
  }
}

}  // namespace

void check_state_of(const Problem& problem, const StateView& view, const char* parameter) {
  const Problem* origin = view.problem.get();
  bool same = origin == &problem;
  if (!same && origin != nullptr) {
    same = origin->deadline() == problem.deadline() && origin->action_count() == problem.action_count() &&
           origin->skeleton_count() == problem.skeleton_count() && origin->chains().size() == problem.chains().size() &&
           origin->has_backtracking() == problem.has_backtracking();
    for (int k = 0; same && k < problem.skeleton_count(); ++k) {
      same = std::ranges::equal(origin->skeleton(k), problem.skeleton(k));
    }
  }
  if (!same) {
    throw UsageError("parameter '" + std::string(parameter) +
                     "': a state of the MDP of another problem (its deadline, actions or skeletons differ)");
  }
}

void bind_mdp(py::module_& m) {
  py::enum_<Status> status(m, "Status", "Where an episode or session stands.");
  status.value("running", Status::running).value("success", Status::success).value("failure", Status::failure);
  // Made from its value only when it is one: pybind11's own constructor takes any int.
  py::delattr(status, "__init__");
  status.def(py::init([](Number<int, "value", 0, 2> value) { return static_cast<Status>(value.value); }),
             py::arg("value"));

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
      .def(
          "__eq__", [](const StateView& a, const StateView& b) { return a.state == b.state; },
          py::is_operator())  // another object: NotImplemented, so False
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
      .def(py::init([](const Required<Problem, "problem">& problem) {
             return std::make_shared<MdpHandle>(problem.pointer);
           }),
           py::arg("problem"))
      .def_property_readonly("problem", [](const MdpHandle& h) { return std::const_pointer_cast<Problem>(h.problem); })
      .def_property_readonly("skeleton_count", [](const MdpHandle& h) { return h.mdp.skeleton_count(); })
      .def_property_readonly("deadline", [](const MdpHandle& h) { return h.mdp.deadline(); })
      .def(
          "start",
          [](const MdpHandle& h) {
            return StateView{h.mdp.start(), h.mdp.skeleton_count(), h.problem};
          },
          "The start state.")
      .def(
          "next_action",
          [](const MdpHandle& h, const StateView& s, Number<int, "skeleton", 0> k) {
            check_state_of(*h.problem, s);
            check_skeleton(h.mdp, k);
            return h.mdp.next_action(s.state, k);
          },
          py::arg("state"), py::arg("skeleton"), "The action skeleton k refines next, or -1 when it is fully refined.")
      .def(
          "useful_choices",
          [](const MdpHandle& h, const StateView& s) {
            check_state_of(*h.problem, s);
            std::vector<int> out;
            for (const int choice : h.mdp.useful_choices(s.state)) out.push_back(choice);
            return out;
          },
          py::arg("state"), "The choices worth considering (one per group sharing a next action), ascending.")
      .def(
          "can_succeed",
          [](const MdpHandle& h, const StateView& s, Number<int, "skeleton", 0> k) {
            check_state_of(*h.problem, s);
            check_skeleton(h.mdp, k);
            return h.mdp.can_succeed(s.state, k);
          },
          py::arg("state"), py::arg("skeleton"), "Whether skeleton k can still meet the deadline from this state.");
}

}  // namespace ontime::python
