// The extension module `ontime._ontime`: the library's errors as Python exceptions, and the
// shared helpers of bindings.hpp. The pure-Python package `ontime` re-exports what is here.

#include <pybind11/pybind11.h>

#include <chrono>
#include <condition_variable>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>
#include <thread>

#include "bindings.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/report/report.hpp"
#include "ontime/util/error.hpp"

namespace ontime::python {

std::shared_ptr<MdpHandle> to_mdp(const py::object& source, const char* parameter) {
  if (py::isinstance<MdpHandle>(source)) return source.cast<std::shared_ptr<MdpHandle>>();
  if (py::isinstance<Problem>(source)) return std::make_shared<MdpHandle>(source.cast<std::shared_ptr<Problem>>());
  if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__")) {
    const std::string path = py::str(py::module_::import("os").attr("fspath")(source));
    std::shared_ptr<Problem> problem;
    {
      const py::gil_scoped_release release;
      problem = std::make_shared<Problem>(load_problem(path));
    }
    return std::make_shared<MdpHandle>(std::move(problem));
  }
  throw UsageError(
      "parameter '" + std::string(parameter) +
      "': must be an ontime.Problem, an ontime.Mdp or the path of an instance file (got " +
      (source.is_none() ? std::string("None") : "a " + std::string(py::str(py::type::of(source).attr("__name__")))) +
      ")");
}

std::string path_argument(const py::handle& value, const char* parameter) {
  if (!py::isinstance<py::str>(value) && !py::hasattr(value, "__fspath__")) {
    throw UsageError(
        "parameter '" + std::string(parameter) + "': must be a path (str or os.PathLike) (got " +
        (value.is_none() ? std::string("None") : "a " + std::string(py::str(py::type::of(value).attr("__name__")))) +
        ")");
  }
  const py::object text = py::module_::import("os").attr("fspath")(value);
  if (!py::isinstance<py::str>(text)) {
    throw UsageError("parameter '" + std::string(parameter) + "': must be a path of text, not bytes");
  }
  std::string path = text.cast<std::string>();
  if (path.empty()) throw UsageError("parameter '" + std::string(parameter) + "': must be a path, not empty text");
  return path;
}

void refuse_number(const char* name, const std::string& rule, py::handle got) {
  std::string shown;
  if (got.is_none()) {
    shown = "None";
  } else if (PyBool_Check(got.ptr())) {
    shown = "a bool";
  } else if (py::isinstance<py::int_>(got) || py::isinstance<py::float_>(got)) {
    shown = py::str(got);
  } else {
    shown = "a " + std::string(py::str(py::type::of(got).attr("__name__")));
  }
  throw UsageError("parameter '" + std::string(name) + "': " + rule + " (got " + shown + ")");
}

void refuse_object(const char* name, py::handle expected_type, py::handle got) {
  const std::string shown = got.is_none() ? "None" : "a " + std::string(py::str(py::type::of(got).attr("__name__")));
  throw UsageError("parameter '" + std::string(name) + "': must be a " +
                   std::string(py::str(expected_type.attr("__name__"))) + " (got " + shown + ")");
}

std::string instance_label(const py::object& source, const Problem& problem) {
  if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__")) {
    return py::str(py::module_::import("os").attr("fspath")(source));
  }
  return problem.name();
}

ParameterValues parameter_values(const py::kwargs& kwargs) {
  ParameterValues values;
  for (const auto& [key, value] : kwargs) {
    std::string name = py::str(key);
    for (char& c : name) {
      if (c == '_') c = '-';
    }
    std::string text;
    if (py::isinstance<py::bool_>(value)) {
      throw UsageError("parameter '" + name + "': expected a number or text, got a bool");
    } else if (py::isinstance<py::float_>(value)) {
      text = py::repr(value);  // the shortest text that reads back as the same double
    } else if (py::isinstance<py::int_>(value) || py::isinstance<py::str>(value)) {
      text = py::str(value);
    } else if (py::hasattr(value, "__fspath__")) {
      text = py::str(py::module_::import("os").attr("fspath")(value));
    } else if (py::hasattr(value, "__len__")) {  // a numpy array has __index__ and __float__, but many numbers
      throw UsageError("parameter '" + name + "': expected a number, text or a path, got a " +
                       std::string(py::str(py::type::of(value).attr("__name__"))));
    } else if (py::hasattr(value, "__index__")) {  // numpy integers
      text = py::str(py::int_(py::reinterpret_borrow<py::object>(value)));
    } else if (py::hasattr(value, "__float__")) {  // numpy floats
      text = py::repr(py::float_(py::reinterpret_borrow<py::object>(value)));
    } else {
      throw UsageError("parameter '" + name + "': expected a number, text or a path, got " +
                       std::string(py::str(py::type::of(value).attr("__name__"))));
    }
    values.set(std::move(name), std::move(text));
  }
  return values;
}

ParameterSpelling python_spelling() {
  return [](std::string_view parameter) {
    std::string name(parameter);
    for (char& c : name) {
      if (c == '-') c = '_';
    }
    return name;
  };
}

py::dict parameters_dict(const std::string& kind_name, const ParameterValues& values) {
  return json_object(report::parameters_json(allocator_registry().find(kind_name), values));
}

py::object json_object(const std::string& text) { return py::module_::import("json").attr("loads")(text); }

std::shared_ptr<AllocatorHandle> make_allocator_handle(std::shared_ptr<MdpHandle> mdp, const std::string& name,
                                                       const ParameterValues& values) {
  auto handle = std::make_shared<AllocatorHandle>();
  handle->mdp = std::move(mdp);
  handle->name = name;
  handle->values = values;
  {
    // A factory may precompute for a long time (optimal solves the whole MDP).
    const py::gil_scoped_release release;
    handle->factory = make_allocator_factory(name, handle->mdp->mdp, values);
    handle->allocator = handle->factory();
  }
  return handle;
}

void check_callable(const py::object& callback, const char* parameter) {
  if (!callback.is_none() && PyCallable_Check(callback.ptr()) == 0) {
    throw UsageError("parameter '" + std::string(parameter) + "': must be callable or None (got a " +
                     std::string(py::str(py::type::of(callback).attr("__name__"))) + ")");
  }
}

void run_interruptibly(const std::function<void(const std::function<bool()>& stop, Progress& progress)>& work,
                       const py::object& progress_callback) {
  check_callable(progress_callback, "progress");
  std::atomic<bool> stop_requested{false};
  const std::function<bool()> stop = [&stop_requested] { return stop_requested.load(std::memory_order_relaxed); };
  Progress progress;
  std::mutex mutex;
  std::condition_variable finished_signal;
  bool finished = false;
  std::exception_ptr failure;
  std::optional<py::error_already_set> interrupt;
  std::uint64_t reported = ~std::uint64_t{0};
  {
    const py::gil_scoped_release release;
    std::thread worker([&] {
      try {
        work(stop, progress);
      } catch (...) {
        failure = std::current_exception();
      }
      const std::lock_guard lock(mutex);
      finished = true;
      finished_signal.notify_all();
    });
    for (;;) {
      std::unique_lock lock(mutex);
      if (finished_signal.wait_for(lock, std::chrono::milliseconds(50), [&] { return finished; })) break;
      lock.unlock();
      const py::gil_scoped_acquire acquire;
      if (!interrupt && PyErr_CheckSignals() != 0) {
        interrupt.emplace();  // fetches the exception the signal handler raised
        stop_requested = true;
      }
      const std::uint64_t done = progress.done.load();
      if (!progress_callback.is_none() && !interrupt && done != reported) {
        reported = done;
        try {
          progress_callback(done, progress.total.load());
        } catch (py::error_already_set& error) {
          interrupt.emplace(std::move(error));
          stop_requested = true;
        }
      }
    }
    worker.join();
  }
  if (interrupt) throw std::move(*interrupt);
  if (failure) std::rethrow_exception(failure);
  if (!progress_callback.is_none() && progress.done.load() != reported) {
    progress_callback(progress.done.load(), progress.total.load());
  }
}

namespace {

// Exception types: ontime.Error and its subclasses, each also a subclass of the built-in
// exception a Python caller would catch for it.
PyObject* g_error = nullptr;
PyObject* g_input_error = nullptr;
PyObject* g_usage_error = nullptr;
PyObject* g_resource_limit_error = nullptr;

PyObject* new_exception(py::module_& m, const char* name, PyObject* builtin, const char* doc) {
  const std::string qualified = std::string("ontime.") + name;
  py::tuple bases = builtin != nullptr ? py::make_tuple(py::handle(g_error), py::handle(builtin))
                                       : py::make_tuple(py::handle(PyExc_Exception));
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (type == nullptr) throw py::error_already_set();
  m.add_object(name, py::handle(type));
  return type;
}

void translate_errors(std::exception_ptr error) {
  try {
    if (error) std::rethrow_exception(error);
  } catch (const InputError& e) {
    py::object exception = py::reinterpret_borrow<py::object>(g_input_error)(e.what());
    exception.attr("source") = e.source();
    exception.attr("place") = e.place();
    exception.attr("rule") = e.rule();
    PyErr_SetObject(g_input_error, exception.ptr());
  } catch (const UsageError& e) {
    PyErr_SetString(g_usage_error, e.what());
  } catch (const ResourceLimitError& e) {
    PyErr_SetString(g_resource_limit_error, e.what());
  } catch (const Cancelled& e) {
    PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
  }
}

}  // namespace

}  // namespace ontime::python

PYBIND11_MODULE(_ontime, m) {
  using namespace ontime::python;
  m.doc() = "OnTime's C++ core (import the package `ontime`, which re-exports it).";
  g_error = new_exception(m, "Error", nullptr, "Base class of the errors OnTime raises.");
  g_input_error = new_exception(
      m, "InputError", PyExc_ValueError,
      "Bad input data: the message names the source (a file), the place in it and the rule broken, as the "
      "command line prints it; also as the attributes `source`, `place` and `rule`.");
  g_usage_error = new_exception(
      m, "UsageError", PyExc_ValueError,
      "A request that cannot be served as asked: an unknown allocator or parameter, a value out of range, an "
      "exact evaluation of an allocator that is not stationary, a session used out of turn.");
  g_resource_limit_error =
      new_exception(m, "ResourceLimitError", PyExc_RuntimeError,
                    "A computation reached a cap (states, memory) before finishing; the message says which.");
  py::register_exception_translator(&translate_errors);
  m.attr("NEVER") = ontime::kNever;
  bind_model(m);
  bind_mdp(m);
  bind_solve(m);
  bind_allocators(m);
  bind_run(m);
  bind_acting(m);
  bind_live(m);
  bind_environment(m);
  bind_learn(m);
  bind_report(m);
  py::module_ domains = m.def_submodule("domains", "OnTime's TAMP domains (OMPL, FCL, KDL), when built.");
  bind_domains(domains);
}
