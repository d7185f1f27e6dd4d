// `ontime solve INSTANCE`: the exact optimum (layered, memoised or branch-and-bound), or a certified
// interval around it when a cap stops the layered solver, a tolerance drops hopeless groups or
// a split bounds the weaker subtrees.

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "cluster_job.hpp"
#include "common.hpp"
#include "memory_limits.hpp"
#include "number_options.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/report/report.hpp"
#include "ontime/solve/concurrent_layered_solver.hpp"
#include "ontime/solve/concurrent_search.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/solve/layered_solver.hpp"
#include "ontime/solve/search_solver.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"

namespace ontime::cli {
namespace {

struct SolveOptions {
  std::string instance;
  std::string method = "layered";
  std::string act;  // empty: the instance's own mode
  std::size_t max_states = 0;
  std::uint64_t max_memory_mib = 0;
  std::uint64_t max_disk_mib = 0;
  std::string scratch;
  std::string policy;
  int policy_layers = 1;
  double max_seconds = 0;
  double tolerance = 0;
  double gap = 0;
  unsigned threads = 0;
  bool stats = false;
  bool json = false;
  bool no_timing = false;
};

void run_memoised(const SolveOptions& options, const Problem& problem, const Mdp& mdp) {
  const std::size_t max_states = options.max_states != 0 ? options.max_states : OptimalSolver::kDefaultMaxStates;
  check_exact_work(problem, max_states, options.instance, flag_spelling());
  const auto started = std::chrono::steady_clock::now();
  OptimalSolver solver(mdp, max_states);
  const double value = solver.solve(mdp.start());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  report::Solve solve{.instance = options.instance, .problem = &problem, .mdp = &mdp, .method = "memoised"};
  solve.memoised = true;
  solve.solution.exact = true;
  solve.solution.lower = solve.solution.upper = value;
  solve.solution.states = solver.states();
  solve.solution.first_choice = solver.best_choice(mdp.start()).value_or(-1);
  solve.seconds = seconds;
  fmt::print("{}", options.json ? report::to_json(solve) + "\n" : report::to_text(solve));
}

// The layered solvers' settings from the command line: threads, the state cap, the memory and
// disk caps (unless given, what this machine can give to each of `ranks`, so that a solve stops
// with an interval rather than being killed), the scratch folder, and the stop once --max-seconds
// have passed since `started`.
LayeredSolveOptions layered_settings(const SolveOptions& options, std::chrono::steady_clock::time_point started,
                                     const Ranks* ranks) {
  LayeredSolveOptions settings;
  settings.ranks = ranks;
  settings.threads = options.threads;
  settings.max_states = options.max_states;
  settings.scratch_directory = options.scratch;
  if (options.max_memory_mib != 0) {
    check_memory_for("--max-memory-mib", static_cast<double>(options.max_memory_mib) * 1048576.0);
    settings.max_memory_bytes = options.max_memory_mib << 20;
  }
  std::error_code error;
  if (!options.scratch.empty() && !std::filesystem::is_directory(options.scratch, error)) {
    throw UsageError("--scratch " + options.scratch + ": not a directory");
  }
  settings.max_disk_bytes = options.max_disk_mib << 20;
  apply_tool_layered_settings(settings);
  if (options.max_seconds > 0) {
    const auto deadline = started + std::chrono::duration<double>(options.max_seconds);
    settings.stop = [deadline] { return std::chrono::steady_clock::now() >= deadline; };
  }
  return settings;
}

// `solve(settings)` with a progress line: layers (levels acting while planning), not a percentage,
// since how many there will be, and how large, is what the solve finds out. The line is cleared
// (the bar destroyed) before the result is printed.
template <class Solve>
auto with_layer_progress(LayeredSolveOptions& settings, const char* layer, Solve&& solve) {
  ProgressBar bar("solve");
  std::uint64_t enumerated = 0;
  settings.on_layer = [&bar, &enumerated, layer](const LayerFigures& figures) {
    if (figures.backward) {
      bar.status(fmt::format("backward pass: {} {} valued ({} states)", layer, figures.layer, figures.states));
    } else {
      enumerated += figures.states;
      bar.status(fmt::format("forward pass: {} {} ({} states) expanded, {} states in all", layer, figures.layer,
                             figures.states, enumerated));
    }
  };
  auto solved = solve(settings);
  settings.on_layer = nullptr;
  return solved;
}

// Acting while planning (SPEC §10): the memoised solver of its MDP, the search or the layered solver.
void run_concurrent(const SolveOptions& options, const Problem& problem, const std::string& method) {
  // The exact solvers' limits (skeletons) hold in this mode too.
  check_exact_work(problem, 1, options.instance, flag_spelling());
  const ConcurrentMdp mdp(problem);
  const auto started = std::chrono::steady_clock::now();
  report::ConcurrentSolve solve{.instance = options.instance, .problem = &problem, .method = method};
  if (method == "layered") {
    LayeredSolveOptions settings = layered_settings(options, started, nullptr);
    solve.solution = with_layer_progress(
        settings, "level", [&](const LayeredSolveOptions& with) { return solve_concurrent_layered(mdp, with); });
  } else {
    ConcurrentSolveOptions settings;
    settings.max_states = options.max_states != 0 ? options.max_states : ConcurrentSolver::kDefaultMaxStates;
    check_memory_for(flag_spelling()("max-states"), ConcurrentSolver::max_bytes(problem, settings.max_states));
    if (method == "search") {
      settings.method = ConcurrentSolveOptions::Method::search;
      settings.gap = options.gap;
      if (options.max_seconds > 0) {
        const auto deadline = started + std::chrono::duration<double>(options.max_seconds);
        settings.stop = [deadline] { return std::chrono::steady_clock::now() >= deadline; };
      }
    }
    solve.solution = solve_concurrent(mdp, settings);
  }
  solve.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  solve.timing = !options.no_timing;
  solve.stats = options.stats;
  fmt::print("{}", options.json ? report::to_json(solve) + "\n" : report::to_text(solve));
}

void run_search(const SolveOptions& options, const Problem& problem, const Mdp& mdp) {
  const std::size_t max_states = options.max_states != 0 ? options.max_states : OptimalSolver::kDefaultMaxStates;
  check_exact_work(problem, max_states, options.instance, flag_spelling());
  SearchSolveOptions settings;
  settings.max_states = max_states;
  settings.gap = options.gap;
  const auto started = std::chrono::steady_clock::now();
  if (options.max_seconds > 0) {
    const auto deadline = started + std::chrono::duration<double>(options.max_seconds);
    settings.stop = [deadline] { return std::chrono::steady_clock::now() >= deadline; };
  }
  report::Solve solve{.instance = options.instance, .problem = &problem, .mdp = &mdp, .method = "search"};
  solve.search = solve_search(mdp, settings);
  solve.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  solve.timing = !options.no_timing;
  fmt::print("{}", options.json ? report::to_json(solve) + "\n" : report::to_text(solve));
}

void run_layered(const SolveOptions& options, const Problem& problem, const Mdp& mdp) {
  const auto started = std::chrono::steady_clock::now();
  LayeredSolveOptions settings = layered_settings(options, started, job_ranks());
  settings.policy_layers = options.policy.empty() ? 0 : options.policy_layers;
  settings.tolerance = options.tolerance;
  settings.split = options.method == "split" ? SplitMode::always : SplitMode::fallback;
  const LayeredSolution solution =
      with_layer_progress(settings, "layer", [&](const LayeredSolveOptions& with) { return solve_layered(mdp, with); });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  report::Solve solve{.instance = options.instance,
                      .problem = &problem,
                      .mdp = &mdp,
                      .method = options.method,
                      .solution = solution,
                      .tolerance = options.tolerance,
                      .seconds = seconds,
                      .timing = !options.no_timing,
                      .stats = options.stats};
  if (!options.policy.empty() && is_root_rank(settings.ranks))
    write_file_atomically(options.policy, report::policy_lines(solve));
  fmt::print("{}", options.json ? report::to_json(solve) + "\n" : report::to_text(solve));
}

}  // namespace

void add_solve_command(CLI::App& app) {
  auto options = std::make_shared<SolveOptions>();
  CLI::App* command = app.add_subcommand(
      "solve", "Exact optimal success probability and first choice, or a certified interval around it");
  command->add_option("INSTANCE", options->instance, "Instance file (JSON, SPEC §5)")->required();
  command
      ->add_option("--method", options->method,
                   "layered (default: the whole tree; where a cap cuts it, a split follows, but for an instance "
                   "with backtracking, rewards, chains or expiry), split (the strongest "
                   "first-action subtree enumerated, the others bounded; "
                   "not with backtracking, rewards, chains or expiry), memoised, or search (branch and bound: exact, "
                   "solving only the states the "
                   "bounds cannot settle)")
      ->check(CLI::IsMember({"layered", "split", "memoised", "search"}));
  CLI::Option* method_option = command->get_option("--method");
  add_act_option(*command, options->act,
                 "Concurrent is solved by --method memoised (the default then), search or layered (levels of CT plus "
                 "the actions started; no split, tolerance nor policy file)");
  add_number_option(*command, "--max-states", options->max_states,
                    "Cap on states: layered and search give an interval past it, memoised stops with an error "
                    "(default: none for layered, 10000000 for memoised and search)",
                    std::size_t{1});
  add_number_option(*command, "--max-memory-mib", options->max_memory_mib,
                    "Layered: tables one rank may hold (default: 80% of the available memory)", std::uint64_t{1});
  add_number_option(*command, "--max-disk-mib", options->max_disk_mib,
                    "Layered: scratch one rank may write (default: 90% of the free space)", std::uint64_t{1});
  add_number_option(*command, "--max-seconds", options->max_seconds,
                    "Layered: end the forward pass after this long and give an interval (the backward pass still "
                    "runs); search: end the search and give an interval",
                    0.0);
  add_number_option(*command, "--gap", options->gap,
                    "Search: no exact solve, but trials of bounded RTDP until the certified interval is at most this "
                    "wide, at least 1e-9 (or --max-states, --max-seconds end them; default 0: the exact search)",
                    0.0, 1.0);
  add_number_option(*command, "--tolerance", options->tolerance,
                    "Layered, split: drop groups whose clairvoyant chance alone is below this, with their share in "
                    "the interval (default 0: none)",
                    0.0, 1.0);
  command->add_option("--scratch", options->scratch, "Layered: directory for the layers' scratch files");
  command->add_option("--policy", options->policy,
                      "Layered: write the choice in every state of the first --policy-layers layers (JSON lines)");
  add_number_option(*command, "--policy-layers", options->policy_layers, "Layers --policy covers (default 1)", 1);
  add_threads_option(*command, options->threads, "Layered: threads per rank (0: one per hardware thread)");
  command->add_flag("--stats", options->stats, "Layered: states and time per layer");
  command->add_flag("--json", options->json, "Print JSON");
  command->add_flag("--no-timing", options->no_timing,
                    "Layered: leave out measured times and memory, so that outputs can be compared byte for byte");
  command->callback([options, command, method_option] {
    if (options->gap > 0 && options->method != "search") throw UsageError("--gap is for --method search");
    if (options->gap > 0 && options->gap < SearchSolveOptions::kFinestGap) {
      throw UsageError("--gap: 0 for the exact search, or at least " +
                       fmt::format("{:g}", SearchSolveOptions::kFinestGap) +
                       " (the finest interval the trials certify; got " + fmt::format("{:g}", options->gap) + ")");
    }
    Problem problem = load_problem(options->instance);
    if (!options->act.empty()) problem = problem.with_acting(*parse_acting(options->act));
    if (problem.acting() == Acting::concurrent) {
      // The memoised solver unless another is asked for.
      const std::string method = method_option->count() > 0 ? options->method : "memoised";
      if (method == "split") {
        throw UsageError(
            "--method split: acting while planning (concurrent, SPEC §10) is solved by --method "
            "memoised, search or layered (a split bounds subtrees plan-first)");
      }
      if (method == "memoised" && command->get_option("--max-seconds")->count() > 0) {
        throw UsageError(
            "--max-seconds: acting while planning (concurrent, SPEC §10) takes it with --method search or layered");
      }
      for (const char* flag : {"--threads", "--max-memory-mib", "--max-disk-mib", "--scratch", "--stats"}) {
        if (method != "layered" && command->get_option(flag)->count() > 0) {
          throw UsageError(std::string(flag) +
                           ": acting while planning (concurrent, SPEC §10) takes it with --method layered");
        }
      }
      for (const char* flag : {"--policy", "--tolerance"}) {
        if (command->get_option(flag)->count() > 0) {
          throw UsageError(std::string(flag) +
                           " is for the plan-first layered solver: acting while planning (concurrent, SPEC §10) is "
                           "solved exactly, and no policy file is written");
        }
      }
      if (split_over_ranks(job_ranks())) {
        throw UsageError("acting while planning (concurrent, SPEC §10) is solved in one process: no MPI ranks");
      }
      run_concurrent(*options, problem, method);
      return;
    }
    if (problem.skeleton_count() > kMaxExactSkeletons) check_exact_work(problem, 1, options->instance);
    const Mdp mdp(problem);
    if (options->method == "memoised") {
      if (split_over_ranks(job_ranks())) {
        throw UsageError("solve --method memoised does not split over MPI ranks: use --method layered");
      }
      run_memoised(*options, problem, mdp);
    } else if (options->method == "search") {
      if (split_over_ranks(job_ranks())) {
        throw UsageError("solve --method search does not split over MPI ranks: use --method layered");
      }
      run_search(*options, problem, mdp);
    } else {
      run_layered(*options, problem, mdp);
    }
  });
}

}  // namespace ontime::cli
