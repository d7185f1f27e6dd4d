// `ontime solve INSTANCE`: the exact optimum (layered or memoised expectimax), or a certified
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
#include "ontime/solve/layered_solver.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"

namespace ontime::cli {
namespace {

struct SolveOptions {
  std::string instance;
  std::string method = "layered";
  std::size_t max_states = 0;
  std::uint64_t max_memory_mib = 0;
  std::uint64_t max_disk_mib = 0;
  std::string scratch;
  std::string policy;
  int policy_layers = 1;
  double max_seconds = 0;
  double tolerance = 0;
  unsigned threads = 0;
  bool stats = false;
  bool json = false;
  bool no_timing = false;
};

std::string first_action_of(const Problem& problem, const Mdp& mdp, int first) {
  return first >= 0 ? problem.action(mdp.next_action(mdp.start(), first)).id : "";
}

Json state_json(const State& state, int skeletons) {
  Json refined = Json::array(), spent = Json::array(), execution = Json::array();
  for (int k = 0; k < skeletons; ++k) {
    const auto slot = static_cast<std::size_t>(k);
    refined.push_back(state.refined[slot]);
    // Blanked slots (skeletons that can no longer succeed) are written as null.
    spent.push_back(state.spent[slot] == 0xFFFF ? Json(nullptr) : Json(state.spent[slot]));
    execution.push_back(state.execution[slot] == 0xFFFF ? Json(nullptr) : Json(state.execution[slot]));
  }
  return Json{{"time", state.time}, {"refined", refined}, {"spent", spent}, {"execution", execution}};
}

void run_memoised(const SolveOptions& options, const Problem& problem, const Mdp& mdp) {
  const std::size_t max_states = options.max_states != 0 ? options.max_states : OptimalSolver::kDefaultMaxStates;
  check_state_cap_memory(problem, max_states, options.instance);
  const auto started = std::chrono::steady_clock::now();
  OptimalSolver solver(mdp, max_states);
  const double value = solver.solve(mdp.start());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const int first = solver.best_choice(mdp.start()).value_or(-1);
  const std::string first_action = first_action_of(problem, mdp, first);
  if (options.json) {
    Json out;
    out["instance"] = options.instance;
    out["name"] = problem.name();
    out["method"] = "memoised";
    out["optimal_success_probability"] = value;
    out["lower_bound"] = value;
    out["upper_bound"] = value;
    out["exact"] = true;
    out["states"] = solver.states();
    out["seconds"] = seconds;
    out["first_choice"] = first;
    out["first_action"] = first_action;
    print_json(out);
    return;
  }
  fmt::print("instance                     {} ({}), deadline {}, {} skeletons\n", options.instance, problem.name(),
             problem.deadline(), problem.skeleton_count());
  fmt::print("optimal success probability  {:.6f}\n", value);
  if (first >= 0) {
    fmt::print("first choice                 skeleton {} (refine {})\n", first, first_action);
  } else {
    fmt::print("first choice                 none (no skeleton can meet the deadline)\n");
  }
  fmt::print("states                       {}\n", solver.states());
  fmt::print("time                         {:.4f} s\n", seconds);
}

void run_layered(const SolveOptions& options, const Problem& problem, const Mdp& mdp) {
  LayeredSolveOptions settings;
  settings.threads = options.threads;
  settings.max_states = options.max_states;
  settings.ranks = job_ranks();
  settings.scratch_directory = options.scratch;
  settings.policy_layers = options.policy.empty() ? 0 : options.policy_layers;
  settings.tolerance = options.tolerance;
  settings.split = options.method == "split" ? SplitMode::always : SplitMode::fallback;
  if (options.max_memory_mib != 0) {
    check_memory_for("--max-memory-mib", static_cast<double>(options.max_memory_mib) * 1048576.0);
    settings.max_memory_bytes = options.max_memory_mib << 20;
  }
  std::error_code error;
  if (!options.scratch.empty() && !std::filesystem::is_directory(options.scratch, error)) {
    throw UsageError("--scratch " + options.scratch + ": not a directory");
  }
  settings.max_disk_bytes = options.max_disk_mib << 20;
  // Unless capped on the command line, stop before the memory and the disk run out.
  apply_tool_layered_settings(settings);
  const auto started = std::chrono::steady_clock::now();
  if (options.max_seconds > 0) {
    const auto deadline = started + std::chrono::duration<double>(options.max_seconds);
    settings.stop = [deadline] { return std::chrono::steady_clock::now() >= deadline; };
  }
  const LayeredSolution solution = [&] {
    // Layers, not a percentage: how many there will be, and how large, is what the solve finds
    // out. The line is cleared (the bar destroyed) before the result is printed.
    ProgressBar bar("solve");
    std::uint64_t enumerated = 0;
    settings.on_layer = [&bar, &enumerated](const LayerFigures& layer) {
      if (layer.backward) {
        bar.status(fmt::format("backward pass: layer {} valued ({} states)", layer.layer, layer.states));
      } else {
        enumerated += layer.states;
        bar.status(fmt::format("forward pass: layer {} ({} states) expanded, {} states in all", layer.layer,
                               layer.states, enumerated));
      }
    };
    LayeredSolution solved = solve_layered(mdp, settings);
    settings.on_layer = nullptr;
    return solved;
  }();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const std::string first_action = first_action_of(problem, mdp, solution.first_choice);

  if (!options.policy.empty() && is_root_rank(settings.ranks)) {
    std::string lines;
    for (const PolicyEntry& entry : solution.policy) {
      Json line = state_json(entry.state, problem.skeleton_count());
      line["choice"] = entry.choice;
      line["lower_bound"] = entry.lower;
      line["upper_bound"] = entry.upper;
      lines += line.dump() + "\n";
    }
    write_file_atomically(options.policy, lines);
  }
  if (options.json) {
    Json out;
    out["instance"] = options.instance;
    out["name"] = problem.name();
    out["method"] = options.method;
    out["optimal_success_probability"] = solution.exact ? Json(solution.lower) : Json(nullptr);
    out["lower_bound"] = solution.lower;
    out["upper_bound"] = solution.upper;
    out["exact"] = solution.exact;
    if (solution.frontier_layer >= 0) {
      out["frontier_layer"] = solution.frontier_layer;
      out["stopped_by"] = solution.stopped_by;
    }
    if (options.tolerance > 0) {
      out["tolerance"] = options.tolerance;
      out["dropped"] = solution.dropped;
    }
    if (!solution.split_kept.empty()) {
      out["split"] = Json{{"enumerated_skeletons", solution.split_kept},
                          {"bounded_start_upper", solution.split_weak_upper},
                          {"lower_bound", solution.split_lower},
                          {"upper_bound", solution.split_upper},
                          {"states", solution.split_states}};
      if (solution.split_frontier_layer >= 0) {
        out["split"]["frontier_layer"] = solution.split_frontier_layer;
        out["split"]["stopped_by"] = solution.split_stopped_by;
      }
    }
    out["states"] = solution.states;
    if (!options.no_timing) out["seconds"] = seconds;
    out["first_choice"] = solution.first_choice;
    out["first_action"] = first_action;
    out["key_bytes"] = solution.key_bytes;
    if (!options.no_timing) {
      out["peak_memory_bytes"] = solution.peak_memory_bytes;
      out["peak_disk_bytes"] = solution.peak_disk_bytes;
    }
    if (options.stats) {
      const auto layers_json = [&](const std::vector<LayerFigures>& of) {
        Json layers = Json::array();
        for (const LayerFigures& layer : of) {
          Json figures{{"layer", layer.layer}, {"states", layer.states}};
          if (!options.no_timing) {
            figures["forward_seconds"] = layer.forward_seconds;
            figures["backward_seconds"] = layer.backward_seconds;
          }
          layers.push_back(figures);
        }
        return layers;
      };
      if (!solution.layers.empty()) out["layers"] = layers_json(solution.layers);
      if (!solution.split_layers.empty()) out["split"]["layers"] = layers_json(solution.split_layers);
    }
    print_json(out);
    return;
  }
  fmt::print("instance                     {} ({}), deadline {}, {} skeletons\n", options.instance, problem.name(),
             problem.deadline(), problem.skeleton_count());
  if (solution.exact) {
    fmt::print("optimal success probability  {:.6f}\n", solution.lower);
  } else {
    fmt::print("optimal success probability  in [{:.6f}, {:.6f}] (width {:.6f})\n", solution.lower, solution.upper,
               solution.upper - solution.lower);
  }
  if (solution.frontier_layer >= 0) fmt::print("whole tree cut               {}\n", solution.stopped_by);
  if (options.tolerance > 0) {
    fmt::print("tolerance                    {} ({} outcomes dropped a group)\n", options.tolerance, solution.dropped);
  }
  if (!solution.split_kept.empty()) {
    fmt::print(
        "split                        skeletons {} enumerated ({} states), the others bounded ({:.6f} at "
        "most alone): [{:.6f}, {:.6f}]\n",
        fmt::join(solution.split_kept, ","), solution.split_states, solution.split_weak_upper, solution.split_lower,
        solution.split_upper);
  }
  if (solution.first_choice >= 0) {
    fmt::print("first choice                 skeleton {} (refine {}){}\n", solution.first_choice, first_action,
               solution.exact ? "" : ", the lower bound's policy");
  } else {
    fmt::print("first choice                 none (no skeleton can meet the deadline)\n");
  }
  fmt::print("states                       {} in {} layers, {} bytes per state\n", solution.states,
             solution.layers.size() + solution.split_layers.size(), solution.key_bytes);
  if (!options.no_timing) {
    fmt::print("peak memory, disk            {:.1f} MiB, {:.1f} MiB\n",
               static_cast<double>(solution.peak_memory_bytes) / 1048576.0,
               static_cast<double>(solution.peak_disk_bytes) / 1048576.0);
    fmt::print("time                         {:.4f} s\n", seconds);
  }
  if (!options.stats) return;
  const auto print_layers = [&](const std::vector<LayerFigures>& layers, const char* title) {
    if (layers.empty()) return;
    fmt::print("\n{}\n", title);
    if (options.no_timing) {
      fmt::print("| layer | states |\n|------:|-------:|\n");
      for (const LayerFigures& layer : layers) fmt::print("| {} | {} |\n", layer.layer, layer.states);
      return;
    }
    fmt::print("| layer | states | forward s | backward s |\n|------:|-------:|----------:|-----------:|\n");
    for (const LayerFigures& layer : layers) {
      fmt::print("| {} | {} | {:.3f} | {:.3f} |\n", layer.layer, layer.states, layer.forward_seconds,
                 layer.backward_seconds);
    }
  };
  print_layers(solution.layers, "whole tree");
  print_layers(solution.split_layers, "split (the enumerated subtree; flagged copies one layer on included)");
}

}  // namespace

void add_solve_command(CLI::App& app) {
  auto options = std::make_shared<SolveOptions>();
  CLI::App* command = app.add_subcommand(
      "solve", "Exact optimal success probability and first choice, or a certified interval around it");
  command->add_option("INSTANCE", options->instance, "Instance file (JSON, SPEC §5)")->required();
  command
      ->add_option("--method", options->method,
                   "layered (default: the whole tree; where a cap cuts it, a split follows), split (the strongest "
                   "first-action subtree enumerated, the others bounded) or memoised")
      ->check(CLI::IsMember({"layered", "split", "memoised"}));
  add_number_option(*command, "--max-states", options->max_states,
                    "Cap on states: layered gives an interval past it, memoised stops with an error (default: "
                    "none for layered, 10000000 for memoised)",
                    std::size_t{1});
  add_number_option(*command, "--max-memory-mib", options->max_memory_mib,
                    "Layered: tables one rank may hold (default: 80% of the available memory)", std::uint64_t{1});
  add_number_option(*command, "--max-disk-mib", options->max_disk_mib,
                    "Layered: scratch one rank may write (default: 90% of the free space)", std::uint64_t{1});
  add_number_option(*command, "--max-seconds", options->max_seconds,
                    "Layered: end the forward pass after this long and give an interval (the backward pass still "
                    "runs)",
                    0.0);
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
  command->callback([options] {
    const Problem problem = load_problem(options->instance);
    if (problem.skeleton_count() > kMaxExactSkeletons) check_state_cap_memory(problem, 1, options->instance);
    const Mdp mdp(problem);
    if (options->method == "memoised") {
      if (split_over_ranks(job_ranks())) {
        throw UsageError("solve --method memoised does not split over MPI ranks: use --method layered");
      }
      run_memoised(*options, problem, mdp);
    } else {
      run_layered(*options, problem, mdp);
    }
  });
}

}  // namespace ontime::cli
