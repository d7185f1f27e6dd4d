#pragma once
// Shared pieces of the Python bindings: the handles that keep C++ objects alive for as long as
// Python refers to them, the translation of parameters given as keyword arguments, and the runner
// of long calls (GIL released, Ctrl-C turned into a stop request).

#include <pybind11/pybind11.h>

#include <atomic>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "ontime/allocator.hpp"
#include "ontime/allocator_registry.hpp"
#include "ontime/error.hpp"
#include "ontime/mdp.hpp"
#include "ontime/problem.hpp"
#include "ontime/state.hpp"

namespace ontime::python {

namespace py = pybind11;

// An Mdp with the Problem it refers to (an Mdp keeps a reference only).
struct MdpHandle {
  explicit MdpHandle(std::shared_ptr<const Problem> p) : problem(std::move(p)), mdp(*problem) {}
  std::shared_ptr<const Problem> problem;
  Mdp mdp;
};

// A State with the number of skeletons it is about, so that Python sees K entries, not 16.
struct StateView {
  State state;
  int skeletons = 0;
};

// Session calls out of turn raise std::logic_error in C++: a usage error for a Python caller.
template <class Call>
auto session_call(Call&& call) {
  try {
    return call();
  } catch (const UsageError&) {
    throw;
  } catch (const std::logic_error& error) {
    throw UsageError(error.what());
  }
}

inline const char* status_name(Status status) {
  switch (status) {
    case Status::running:
      return "running";
    case Status::success:
      return "success";
    case Status::failure:
      return "failure";
  }
  return "?";
}

// A decision as Python sees it; the problem names its action.
struct DecisionView {
  int skeleton = -1;
  int action = -1;
  std::shared_ptr<const Problem> problem;
};

// An MdpHandle from a Problem, an Mdp or a path to an instance file (loaded).
std::shared_ptr<MdpHandle> to_mdp(const py::object& source);
// The instance's file name when `source` is a path, else the problem's name (the `instance` field
// of the results, as the command line reports it).
std::string instance_label(const py::object& source, const Problem& problem);

// One allocator and the factory that made it (threads of a run get their own from the factory).
struct AllocatorHandle {
  std::shared_ptr<MdpHandle> mdp;
  std::string name;
  ParameterValues values;
  AllocatorFactory factory;
  std::unique_ptr<Allocator> allocator;
};

// Keyword arguments as registry parameter values: `max_states=5` is `max-states` = "5".
ParameterValues parameter_values(const py::kwargs& kwargs);
// The kind's parameters, defaults filled in, as the command line's JSON reports them.
py::dict parameters_dict(const std::string& kind, const ParameterValues& values);
std::shared_ptr<AllocatorHandle> make_allocator_handle(std::shared_ptr<MdpHandle> mdp, const std::string& name,
                                                       const ParameterValues& values);

// Runs `work(stop)` on a thread of its own with the GIL released while this thread waits, checking
// for signals every 50 ms. On Ctrl-C (or any signal handler that raises) `stop()` starts returning
// true; `work` is expected to end soon after (by throwing ontime::Cancelled), and the Python
// exception (KeyboardInterrupt) is raised here once it has. `progress`, when given, is called on
// this thread, GIL held, with what `work` reported through the counters it is handed.
struct Progress {
  std::atomic<std::uint64_t> done{0};
  std::atomic<std::uint64_t> total{0};
};
void run_interruptibly(const std::function<void(const std::function<bool()>& stop, Progress& progress)>& work,
                       const py::object& progress_callback = py::none());

void bind_model(py::module_& m);
void bind_running(py::module_& m);
void bind_environment(py::module_& m);
void bind_live(py::module_& m);
void bind_domains(py::module_& m);

}  // namespace ontime::python
