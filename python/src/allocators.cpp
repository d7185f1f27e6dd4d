// Bindings of the allocators layer: allocators made from the registry, their decisions within a
// budget and their counters, and the registry's description of itself.

#include <pybind11/stl.h>

#include <optional>

#include "bindings.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/report/report.hpp"
#include "ontime/util/error.hpp"

namespace ontime::python {

DecisionBudget budget_of(std::optional<Iterations> iterations, std::optional<Seconds> seconds) {
  if (iterations && seconds) return DecisionBudget::either(*iterations, *seconds);
  if (iterations) return DecisionBudget::iterations(*iterations);
  if (seconds) return DecisionBudget::seconds(*seconds);
  return {};
}

py::dict statistics_dict(const Statistics& statistics) {
  py::dict out;
  for (const Statistics::Counter& counter : statistics.counters()) out[py::str(counter.name)] = counter.value;
  return out;
}

void bind_allocators(py::module_& m) {
  py::class_<AllocatorHandle, std::shared_ptr<AllocatorHandle>>(
      m, "Allocator",
      "An effort allocator of the registry, made by ontime.make_allocator. One allocator serves one session "
      "at a time; episode runs make their own per thread from the same kind and parameters.")
      .def_property_readonly(
          "name", [](const AllocatorHandle& h) { return h.name; }, "The registry name of its kind.")
      .def_property_readonly(
          "parameters", [](const AllocatorHandle& h) { return parameters_dict(h.name, h.values); },
          "Its parameters, defaults filled in (registry names, text values).")
      .def_property_readonly(
          "capabilities",
          [](const AllocatorHandle& h) { return allocator_registry().find(h.name).capabilities.names(); })
      .def_property_readonly("mdp", [](const AllocatorHandle& h) { return h.mdp; })
      .def_property_readonly(
          "is_stationary", [](const AllocatorHandle& h) { return h.allocator->is_stationary(); },
          "True when its choice is a function of the state alone (exact evaluation applies).")
      .def(
          "begin_episode", [](AllocatorHandle& h, Seed seed) { h.allocator->begin_episode(seed); }, py::arg("seed"),
          "Starts a new episode; `seed` seeds its randomness.")
      .def(
          "choose",
          [](AllocatorHandle& h, const StateView& state, std::optional<Iterations> iterations,
             std::optional<Seconds> seconds) {
            check_state_of(*h.mdp->problem, state);
            const DecisionBudget budget = budget_of(iterations, seconds);
            const py::gil_scoped_release release;
            return h.allocator->choose(state.state, budget);
          },
          py::arg("state"), py::kw_only(), py::arg("iterations") = py::none(), py::arg("seconds") = py::none(),
          "The skeleton to spend the next step on in `state`, within the budget given (anytime allocators; "
          "unset: the allocator's own).")
      .def(
          "statistics",
          [](const AllocatorHandle& h) {
            Statistics statistics;
            h.allocator->collect_statistics(statistics);
            return statistics_dict(statistics);
          },
          "Its counters (e.g. mcts iterations) since it was made.")
      .def("__repr__", [](const AllocatorHandle& h) { return "ontime.Allocator('" + h.name + "')"; });

  m.def(
      "make_allocator",
      [](const py::object& mdp, const std::string& name, const py::kwargs& kwargs) {
        return make_allocator_handle(to_mdp(mdp, "mdp"), name, parameter_values(kwargs));
      },
      py::arg("mdp"), py::arg("name"),
      "Makes the allocator `name` of the registry for an Mdp (or a Problem, or an instance path), with its "
      "parameters as keyword arguments, '_' for '-': make_allocator(mdp, 'mcts', iterations=2000). "
      "ontime.allocators() lists the kinds and their parameters. Raises UsageError for an unknown name or a "
      "bad value.");

  m.def(
      "allocators", [] { return json_object(report::registry_json(allocator_registry())); },
      "The allocator kinds of the registry with their capabilities and parameters, as `ontime allocators "
      "--json` lists them. Parameters are passed as keyword arguments with '_' for '-' (max_states=...).");
}

}  // namespace ontime::python
