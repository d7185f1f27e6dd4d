// Bindings of the solve layer: the exact optimum or its certified interval (the layered solver,
// with the command line's caps and report), and the knapsack reduction of Theorem 1.

#include <pybind11/stl.h>

#include <chrono>
#include <filesystem>
#include <optional>

#include "bindings.hpp"
#include "ontime/report/report.hpp"
#include "ontime/solve/concurrent_layered_solver.hpp"
#include "ontime/solve/concurrent_search.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/solve/knapsack.hpp"
#include "ontime/solve/layered_solver.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/solve/search_solver.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/memory.hpp"

namespace ontime::python {

std::shared_ptr<const Problem> problem_with_acting(const py::object& source, const std::optional<std::string>& act,
                                                   const char* parameter) {
  std::shared_ptr<const Problem> problem;
  if (py::isinstance<MdpHandle>(source)) {
    problem = source.cast<std::shared_ptr<MdpHandle>>()->problem;
  } else if (py::isinstance<Problem>(source)) {
    problem = source.cast<std::shared_ptr<Problem>>();
  } else if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__")) {
    // Read as a problem, not an Mdp: an instance whose "acting" is concurrent makes no Mdp.
    const std::string path = py::str(py::module_::import("os").attr("fspath")(source));
    const py::gil_scoped_release release;
    problem = std::make_shared<const Problem>(load_problem(path));
  } else {
    problem = to_mdp(source, parameter)->problem;  // raises the error that names what `parameter` may be
  }
  if (!act) return problem;
  const std::optional<Acting> acting = parse_acting(*act);
  if (!acting) throw UsageError("act must be 'plan-first' or 'concurrent' (got '" + *act + "')");
  return acting == problem->acting() ? problem : std::make_shared<const Problem>(problem->with_acting(*acting));
}

void bind_solve(py::module_& m) {
  m.def(
      "reduce_knapsack",
      [](const py::object& knapsack, const std::optional<std::string>& name) {
        const bool is_file = py::isinstance<py::str>(knapsack) || py::hasattr(knapsack, "__fspath__");
        if (!is_file && !py::isinstance(knapsack, py::module_::import("collections.abc").attr("Mapping"))) {
          throw UsageError("parameter 'knapsack': must be a path or a dict {'capacity': W, 'items': [...]} (got " +
                           (knapsack.is_none() ? std::string("None")
                                               : "a " + std::string(py::str(py::type::of(knapsack).attr("__name__")))) +
                           ")");
        }
        const std::string source = is_file ? path_argument(knapsack, "knapsack") : "<knapsack>";
        std::string text;
        if (!is_file) {
          try {
            text = py::str(py::module_::import("json").attr("dumps")(knapsack));
          } catch (py::error_already_set& error) {
            if (!error.matches(PyExc_TypeError) && !error.matches(PyExc_ValueError) &&
                !error.matches(PyExc_RecursionError)) {
              throw;
            }
            throw InputError(source, "top level", std::string("cannot be written as JSON: ") + error.what());
          }
        }
        const py::gil_scoped_release release;
        const Knapsack parsed = is_file ? load_knapsack(source) : parse_knapsack(text, source);
        const std::string problem_name =
            name ? *name : (is_file ? std::filesystem::path(source).stem().string() : "knapsack-reduction");
        return std::make_shared<Problem>(reduce_knapsack(parsed, problem_name));
      },
      py::arg("knapsack"), py::kw_only(), py::arg("name") = py::none(),
      "The effort-allocation instance of Theorem 1 for a knapsack problem (a file, or a dict {'capacity': W, "
      "'items': [{'weight': w, 'value': v}, ...]}), as `ontime reduce-knapsack` writes it; named after the file "
      "unless `name` is given. Its optimum orders the knapsack's solutions by value (docs/theory.md).");

  m.def(
      "solve",
      [](const py::object& problem, Number<std::uint64_t, "max_states", 1> max_states, Threads threads,
         const std::optional<std::string>& method_given, Number<double, "tolerance", 0.0, 1.0> tolerance,
         Number<std::uint64_t, "max_memory_mib", 0, (std::uint64_t{1} << 40)> max_memory_mib,
         Number<std::uint64_t, "max_disk_mib", 0, (std::uint64_t{1} << 40)> max_disk_mib, const py::object& scratch,
         const py::object& policy, Number<int, "policy_layers", 1, 1'000'000> policy_layers,
         Number<double, "gap", 0.0, 1.0> gap, const py::object& act_given) {
        if (!act_given.is_none() && !py::isinstance<py::str>(act_given)) {
          throw UsageError("act must be 'plan-first' or 'concurrent' (got " + std::string(py::repr(act_given)) + ")");
        }
        const std::optional<std::string> act =
            act_given.is_none() ? std::nullopt : std::optional<std::string>(act_given.cast<std::string>());
        // An Mdp is plan-first by construction; anything else is read as a problem with its mode.
        const std::shared_ptr<const Problem> chosen =
            act || !py::isinstance<MdpHandle>(problem) ? problem_with_acting(problem, act) : nullptr;
        // Both layered solvers' options: caps not given are what this machine can give, so that a
        // solve stops with a certified interval rather than being killed (as the command line does).
        const auto layered_options = [&] {
          LayeredSolveOptions options;
          options.max_states = max_states;
          options.threads = threads;
          if (!scratch.is_none()) options.scratch_directory = path_argument(scratch, "scratch");
          if (max_memory_mib > 0) {
            check_memory_for("max_memory_mib", static_cast<double>(max_memory_mib) * 1048576.0);
            options.max_memory_bytes = max_memory_mib << 20;
          }
          options.max_disk_bytes = max_disk_mib << 20;
          fill_default_caps(options);
          return options;
        };
        if (chosen && chosen->acting() == Acting::concurrent) {
          const std::string method = method_given.value_or("memoised");
          if (method != "memoised" && method != "search" && method != "layered") {
            throw UsageError("method '" + method +
                             "': acting while planning (act='concurrent', SPEC §10) is solved by method='memoised', "
                             "'search' or 'layered'");
          }
          if (gap > 0 && method != "search") throw UsageError("gap is for method='search'");
          if ((max_memory_mib > 0 || max_disk_mib > 0 || !scratch.is_none()) && method != "layered") {
            throw UsageError(
                "max_memory_mib, max_disk_mib and scratch: acting while planning (act='concurrent', "
                "SPEC §10) takes them with method='layered'");
          }
          if (tolerance > 0 || !policy.is_none()) {
            throw UsageError(
                "tolerance and policy are for the plan-first layered solver: acting while planning "
                "(act='concurrent', SPEC §10) is solved exactly, and no policy file is written");
          }
          check_exact_work(*chosen, 1, instance_label(problem, *chosen), python_spelling());
          report::ConcurrentSolve solve{
              .instance = instance_label(problem, *chosen), .problem = chosen.get(), .method = method};
          const ConcurrentMdp concurrent(*chosen);
          LayeredSolveOptions by_levels;
          ConcurrentSolveOptions options;
          if (method == "layered") {
            by_levels = layered_options();
          } else {
            check_memory_for("max_states", ConcurrentSolver::max_bytes(*chosen, max_states));
            options.max_states = max_states;
            options.method =
                method == "search" ? ConcurrentSolveOptions::Method::search : ConcurrentSolveOptions::Method::memoised;
            options.gap = gap;
          }
          run_interruptibly([&](const std::function<bool()>& stop, Progress&) {
            const auto started = std::chrono::steady_clock::now();
            by_levels.stop = options.stop = stop;
            solve.solution = method == "layered" ? solve_concurrent_layered(concurrent, by_levels)
                                                 : solve_concurrent(concurrent, options);
            solve.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
          });
          return json_object(report::to_json(solve));
        }
        const std::shared_ptr<MdpHandle> mdp = chosen ? std::make_shared<MdpHandle>(chosen) : to_mdp(problem);
        const std::string method = method_given.value_or("layered");
        if (gap > 0 && method != "search") throw UsageError("gap is for method='search'");
        if (method != "layered" && method != "split" && method != "memoised" && method != "search") {
          throw UsageError("method must be 'layered', 'split', 'memoised' or 'search' (got '" + method + "')");
        }
        if (method == "search") {
          report::Solve solve{.instance = instance_label(problem, *mdp->problem),
                              .problem = mdp->problem.get(),
                              .mdp = &mdp->mdp,
                              .method = method};
          run_interruptibly([&](const std::function<bool()>& stop, Progress&) {
            const auto started = std::chrono::steady_clock::now();
            SearchSolveOptions options;
            options.max_states = max_states;
            options.stop = stop;
            options.gap = gap;
            solve.search = solve_search(mdp->mdp, options);
            solve.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
          });
          return json_object(report::to_json(solve));
        }
        if (method == "memoised") {
          report::Solve solve{.instance = instance_label(problem, *mdp->problem),
                              .problem = mdp->problem.get(),
                              .mdp = &mdp->mdp,
                              .method = method};
          {
            const py::gil_scoped_release release;
            const auto started = std::chrono::steady_clock::now();
            OptimalSolver solver(mdp->mdp, max_states);
            const double value = solver.solve(mdp->mdp.start());
            solve.memoised = true;
            solve.solution.exact = true;
            solve.solution.lower = solve.solution.upper = value;
            solve.solution.states = solver.states();
            solve.solution.first_choice = solver.best_choice(mdp->mdp.start()).value_or(-1);
            solve.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
          }
          return json_object(report::to_json(solve));
        }
        LayeredSolveOptions options = layered_options();
        options.tolerance = tolerance;
        options.split = method == "split" ? SplitMode::always : SplitMode::fallback;
        if (!policy.is_none()) options.policy_layers = policy_layers;
        report::Solve solve{.instance = instance_label(problem, *mdp->problem),
                            .problem = mdp->problem.get(),
                            .mdp = &mdp->mdp,
                            .method = method,
                            .tolerance = tolerance};
        run_interruptibly([&](const std::function<bool()>& stop, Progress&) {
          const auto started = std::chrono::steady_clock::now();
          options.stop = stop;
          solve.solution = solve_layered(mdp->mdp, options);
          solve.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
        });
        if (!policy.is_none()) {
          write_file_atomically(path_argument(policy, "policy"), report::policy_lines(solve));
        }
        return json_object(report::to_json(solve));
      },
      py::arg("problem"), py::arg("max_states") = OptimalSolver::kDefaultMaxStates, py::arg("threads") = 0,
      py::kw_only(), py::arg("method") = py::none(), py::arg("tolerance") = 0.0, py::arg("max_memory_mib") = 0,
      py::arg("max_disk_mib") = 0, py::arg("scratch") = py::none(), py::arg("policy") = py::none(),
      py::arg("policy_layers") = 1, py::arg("gap") = 0.0, py::arg("act") = py::none(),
      "The exact optimal success probability (or expected reward) and first choice (the layered solver), as "
      "`ontime solve --json` reports them; where a cap cuts the whole tree, a "
      "certified interval [lower_bound, upper_bound] "
      "instead (optimal_success_probability None), tightened by a split when the skeletons' first actions "
      "differ. method='split' splits straight away (the strongest first-action subtree enumerated, the others "
      "bounded); tolerance > 0 drops groups whose clairvoyant chance is below it, with their share in the "
      "interval. Caps: max_states, max_memory_mib (tables of this process) and max_disk_mib (its scratch files, "
      "in `scratch`, default the system's temporary folder); 0: 80% of the available memory and 90% of the free "
      "disk. policy=FILE writes the choices of the first `policy_layers` layers as `ontime solve --policy` does "
      "(JSON Lines: a state, its choice and the bounds of its value). The GIL is released; Ctrl-C stops it "
      "(KeyboardInterrupt). method='memoised' is the memoised expectimax (OptimalSolver: exact, or an error past "
      "max_states). method='search' is the branch-and-bound search (exact as the others, touching fewer states; past "
      "max_states a certified interval, as `ontime solve --method search`); with gap > 0 it solves nothing exactly but "
      "runs trials of bounded RTDP until the certified interval is at most `gap` wide (`ontime solve --gap`). For an "
      "instance with backtracking neither "
      "a split nor a tolerance applies (UsageError), and "
      "a cap's interval comes from bounds that count a give-up as a success. act='concurrent' (or an instance "
      "whose \"acting\" is concurrent) solves acting while planning (SPEC §10: the robot executes refined actions "
      "while the rest is planned) with the memoised solver of that model, as `ontime solve --act concurrent`, or "
      "with method='search' or method='layered' (levels of CT plus the actions started, on `threads`, with "
      "the layered solver's caps and scratch; cut by one, a certified interval); the "
      "result then has \"acting\": \"concurrent\". act='plan-first' reads any instance as plan-first.");
}

}  // namespace ontime::python
