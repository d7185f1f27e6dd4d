// Bindings of the mdp layer: the MDP of a problem (transitions, choices, liveness), its states and
// the status of an episode.

#include "ontime/mdp/mdp.hpp"

#include <pybind11/operators.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "ontime/mdp/state.hpp"

namespace ontime::python {

namespace {

template <class Array>
py::list first(const Array& values, int count) {
  py::list out;
  for (int k = 0; k < count; ++k) out.append(values[static_cast<std::size_t>(k)]);
  return out;
}

}  // namespace

void bind_mdp(py::module_& m) {
  py::enum_<Status>(m, "Status", "Where an episode or session stands.")
      .value("running", Status::running)
      .value("success", Status::success)
      .value("failure", Status::failure);

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
}

}  // namespace ontime::python
