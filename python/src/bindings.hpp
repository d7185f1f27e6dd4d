#pragma once
// Shared pieces of the Python bindings: the handles that keep C++ objects alive for as long as
// Python refers to them, the translation of parameters given as keyword arguments, and the runner
// of long calls (GIL released, Ctrl-C turned into a stop request).

#include <pybind11/pybind11.h>

#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/mdp/state.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/world.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/memory.hpp"

namespace ontime::python {

namespace py = pybind11;

// ---- numeric arguments that know their name and range ----
// pybind11 answers a negative count or a seed of 2**64 with a TypeError that lists signatures.
// A parameter declared as Number<T, "name", min, max> takes any Python int (or, for reals, any
// int or float; numpy scalars through __index__ / __float__) and raises UsageError naming the
// parameter and its rule otherwise, as the command line and make_allocator do.
template <std::size_t N>
struct ParameterName {
  char text[N]{};
  constexpr ParameterName(const char (&name)[N]) {  // NOLINT: implicit, for template arguments
    for (std::size_t i = 0; i < N; ++i) text[i] = name[i];
  }
};

template <class T, ParameterName Name, T Min = std::numeric_limits<T>::lowest(), T Max = std::numeric_limits<T>::max()>
struct Number {
  static_assert(std::is_arithmetic_v<T> && !std::is_same_v<T, bool>);
  T value{};
  operator T() const noexcept { return value; }  // NOLINT: used as the number it holds
};

// "parameter 'NAME': RULE (got WHAT)" as a UsageError.
[[noreturn]] void refuse_number(const char* name, const std::string& rule, py::handle got);

template <class T>
std::string number_rule(T min, T max) {
  const auto text = [](T x) {
    if constexpr (std::is_integral_v<T>) {
      return std::to_string(x);
    } else {
      return std::string(py::str(py::float_(static_cast<double>(x))));
    }
  };
  const char* kind = std::is_integral_v<T>     ? "must be a whole number"
                     : std::isinf(double(max)) ? "must be a number"
                                               : "must be a finite number";
  const bool low = min != std::numeric_limits<T>::lowest();
  // A whole number of 32 bits or fewer shows its top, which a Python int passes easily.
  const bool high = max != std::numeric_limits<T>::max() || (std::is_integral_v<T> && sizeof(T) < 8);
  if (!low && !high && !std::is_integral_v<T>) return kind;
  if (low && !high) return std::string(kind) + " >= " + text(min);
  if (!low && high && !std::is_integral_v<T>) return std::string(kind) + " <= " + text(max);
  return std::string(kind) + " from " + text(min) + " to " + text(max);
}

// Seeds, counts and thread counts, named as the functions name them.
using Seed = Number<std::uint64_t, "seed">;
using Episodes = Number<std::uint64_t, "episodes", 1>;
using Threads = Number<unsigned, "threads", 0, 1024>;
using Iterations = Number<std::uint64_t, "iterations", 1>;
using Seconds = Number<double, "seconds", 0.0>;

// ---- object arguments that know their name ----
// pybind11 passes None to a std::shared_ptr parameter as an empty pointer (the call would then
// dereference it) and answers an object of another type with a TypeError listing signatures. A
// parameter declared as Required<T, "name"> takes only a T (a class the module binds) and raises
// UsageError naming the parameter and the class otherwise.
template <class T, ParameterName Name>
struct Required {
  std::shared_ptr<T> pointer;  // never empty once loaded
  T& operator*() const noexcept { return *pointer; }
  T* operator->() const noexcept { return pointer.get(); }
  operator const std::shared_ptr<T>&() const noexcept { return pointer; }  // NOLINT: used as the pointer it holds
};

// "parameter 'NAME': must be a CLASS (got WHAT)" as a UsageError.
[[noreturn]] void refuse_object(const char* name, py::handle expected_type, py::handle got);

// An Mdp with the Problem it refers to (an Mdp keeps a reference only).
struct MdpHandle {
  explicit MdpHandle(std::shared_ptr<const Problem> p) : problem(std::move(p)), mdp(*problem) {}
  std::shared_ptr<const Problem> problem;
  Mdp mdp;
};

// The chains' states a caller reports after a step ({chain: state}, by name; SPEC §9): the
// observation with their joint state, which an instance with chains needs (UsageError without)
// and one without refuses; and the states of a joint state, by name.
using ChainStates = std::optional<std::map<std::string, std::string>>;
Observation with_reported_chains(const Mdp& mdp, Observation observation, const ChainStates& reported);
std::map<std::string, std::string> chain_states(const Mdp& mdp, std::uint16_t joint);

// A State with the number of skeletons it is about, so that Python sees K entries, not 16, and
// the problem of the MDP it is a state of.
struct StateView {
  State state;
  int skeletons = 0;
  std::shared_ptr<const Problem> problem;
};

// UsageError naming `parameter` unless `state` is a state of an MDP of `problem` (or of a problem
// with the same deadline, actions and skeletons): the MDP's tables are indexed by its values.
void check_state_of(const Problem& problem, const StateView& state, const char* parameter = "state");

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

// An MdpHandle from a Problem, an Mdp or a path to an instance file (loaded); UsageError naming
// `parameter` for anything else.
std::shared_ptr<MdpHandle> to_mdp(const py::object& source, const char* parameter = "problem");
// The problem `source` names (a Problem, an Mdp's problem, or an instance path), with the acting
// mode `act` when given ("plan-first" or "concurrent"; SPEC §10): read as a problem, not an Mdp,
// since an instance whose "acting" is concurrent makes no Mdp.
std::shared_ptr<const Problem> problem_with_acting(const py::object& source, const std::optional<std::string>& act,
                                                   const char* parameter = "problem");
// The text of a path argument (str or os.PathLike); UsageError naming `parameter` for anything else
// and for empty text.
std::string path_argument(const py::handle& value, const char* parameter);
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
// Parameters as Python writes them in the library's messages: "max_states".
ParameterSpelling python_spelling();
// The kind's parameters, defaults filled in, as the command line's JSON reports them.
py::dict parameters_dict(const std::string& kind, const ParameterValues& values);

// A JSON text of the report module (report/report.hpp) as Python objects (json.loads), so that
// Python returns what the command line prints.
py::object json_object(const std::string& text);

// An evaluation's report (report::Evaluation) as a dict: the fields of `ontime evaluate --json`.
py::dict monte_carlo_dict(const std::string& solver, const ParameterValues& values, const std::string& instance,
                          const Problem& problem, const MonteCarloResult& result, std::uint64_t seed,
                          const std::optional<ExactEvaluation>& exact = std::nullopt);
std::shared_ptr<AllocatorHandle> make_allocator_handle(std::shared_ptr<MdpHandle> mdp, const std::string& name,
                                                       const ParameterValues& values);

// UsageError naming `parameter` unless `callback` is None or callable.
void check_callable(const py::object& callback, const char* parameter);

// Runs `work(stop)` on a thread of its own with the GIL released while this thread waits, checking
// for signals every 50 ms. On Ctrl-C (or any signal handler that raises) `stop()` starts returning
// true; `work` is expected to end soon after (by throwing ontime::Cancelled), and the Python
// exception (KeyboardInterrupt) is raised here once it has. `progress`, when given, is called on
// this thread, GIL held, with what `work` reported through the counters it is handed; a
// `progress` that is neither None nor callable is a UsageError naming it, before `work` starts.
struct Progress {
  std::atomic<std::uint64_t> done{0};
  std::atomic<std::uint64_t> total{0};
};
void run_interruptibly(const std::function<void(const std::function<bool()>& stop, Progress& progress)>& work,
                       const py::object& progress_callback = py::none());

// The bindings, one file per layer of the library (python/src/LAYER.cpp; live.cpp and
// environment.cpp are the run layer's live sessions and Gymnasium-style environment).
void bind_model(py::module_& m);
void bind_mdp(py::module_& m);
void bind_solve(py::module_& m);
void bind_allocators(py::module_& m);
void bind_run(py::module_& m);
void bind_acting(py::module_& m);
void bind_live(py::module_& m);
void bind_environment(py::module_& m);
void bind_learn(py::module_& m);
void bind_report(py::module_& m);
void bind_domains(py::module_& m);

// Helpers the layers' bindings share.
// A decision budget from Python's keyword arguments (neither: unset, the allocator's own).
DecisionBudget budget_of(std::optional<Iterations> iterations, std::optional<Seconds> seconds);
// Counters as a dict, by name.
py::dict statistics_dict(const Statistics& statistics);
// UsageError for zero episodes.
void check_episodes(std::uint64_t episodes);
// Planner-log records as a list of dicts (the keys of docs/formats.md).
py::list attempts_list(const std::vector<RefinementAttempt>& attempts);
// Episodes in `worlds` and, when `exact`, the exact evaluation of the allocator (Ctrl-C stops
// both), with `progress(done, total)` called now and then.
std::pair<MonteCarloResult, std::optional<ExactEvaluation>> run_and_evaluate(
    const MdpHandle& mdp, const WorldFactory& worlds, const AllocatorFactory& factory, const MonteCarloOptions& options,
    bool exact, const ParameterValues& values, const py::object& progress);

}  // namespace ontime::python

namespace pybind11::detail {

template <class T, ontime::python::ParameterName Name, T Min, T Max>
struct type_caster<ontime::python::Number<T, Name, Min, Max>> {
  using Value = ontime::python::Number<T, Name, Min, Max>;
  PYBIND11_TYPE_CASTER(Value, const_name<std::is_integral_v<T>>("int", "float"));

  bool load(handle source, bool /*convert*/) {
    PyObject* object = source.ptr();
    const std::string rule = ontime::python::number_rule<T>(Min, Max);
    if (object == nullptr || PyBool_Check(object)) ontime::python::refuse_number(Name.text, rule, source);
    if constexpr (std::is_integral_v<T>) {
      if (!PyIndex_Check(object)) ontime::python::refuse_number(Name.text, rule, source);
      const auto whole = reinterpret_steal<pybind11::int_>(PyNumber_Index(object));
      if (!whole) {
        PyErr_Clear();  // e.g. a numpy array of several numbers
        ontime::python::refuse_number(Name.text, rule, source);
      }
      if (whole < pybind11::int_(Min) || whole > pybind11::int_(Max))
        ontime::python::refuse_number(Name.text, rule, source);
      value.value = pybind11::cast<T>(whole);
    } else {
      if (!PyFloat_Check(object) && !PyLong_Check(object) && !hasattr(source, "__float__")) {
        ontime::python::refuse_number(Name.text, rule, source);
      }
      const double real = PyFloat_AsDouble(object);
      if (real == -1.0 && PyErr_Occurred() != nullptr) {
        PyErr_Clear();  // e.g. an int too large for a double
        ontime::python::refuse_number(Name.text, rule, source);
      }
      // Infinity only where the range ends there (an execution time that cannot be executed).
      const bool infinite_allowed = std::isinf(static_cast<double>(Max));
      if (std::isnan(real) || (std::isinf(real) && !(infinite_allowed && real > 0)) ||
          real < static_cast<double>(Min) || real > static_cast<double>(Max)) {
        ontime::python::refuse_number(Name.text, rule, source);
      }
      value.value = static_cast<T>(real);
    }
    return true;
  }

  static handle cast(const Value& number, return_value_policy, handle) {
    if constexpr (std::is_integral_v<T>) {
      return pybind11::int_(number.value).release();
    } else {
      return pybind11::float_(static_cast<double>(number.value)).release();
    }
  }
};

template <class T, ontime::python::ParameterName Name>
struct type_caster<ontime::python::Required<T, Name>> {
  using Value = ontime::python::Required<T, Name>;
  PYBIND11_TYPE_CASTER(Value, const_name("object"));

  bool load(handle source, bool /*convert*/) {
    const pybind11::type expected = pybind11::type::of<T>();
    if (!source || source.is_none() || !isinstance(source, expected)) {
      ontime::python::refuse_object(Name.text, expected, source);
    }
    value.pointer = pybind11::cast<std::shared_ptr<T>>(source);
    return true;
  }

  static handle cast(const Value& object, return_value_policy policy, handle parent) {
    return make_caster<std::shared_ptr<T>>::cast(object.pointer, policy, parent);
  }
};

}  // namespace pybind11::detail
