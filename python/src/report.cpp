// Bindings of the report layer's data that no other function returns: the histograms' CSV.

#include "ontime/report/report.hpp"

#include <pybind11/stl.h>

#include "bindings.hpp"

namespace ontime::python {

void bind_report(py::module_& m) {
  m.def(
      "histogram_csv", [](const py::object& problem) { return report::histogram_csv(*to_mdp(problem)->problem); },
      py::arg("problem"),
      "Every action's planning and execution PMF as the CSV `ontime plot` writes beside its picture "
      "(action,distribution,step,probability; 'never' last); python/plot_histograms.py --data CSV draws it.");
}

}  // namespace ontime::python
