#include "ontime/run/table.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <system_error>

#include "ontime/allocators/optimal.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/parallel.hpp"

namespace ontime {
namespace {

// Runs an exact computation that returns (value, states); a ResourceLimitError becomes a
// reached cap of `max_states`.
template <class Compute>
ExactPart exact_part(std::size_t max_states, const Compute& compute) {
  ExactPart part;
  const auto started = std::chrono::steady_clock::now();
  try {
    const auto [value, states] = compute();
    part.value = value;
    part.states = states;
  } catch (const ResourceLimitError&) {
    part.cap_reached = true;
    part.states = max_states;
  }
  part.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return part;
}

bool needs_exact_work(const TableOptions& options, const std::vector<std::string>& solvers) {
  return options.exact || std::any_of(solvers.begin(), solvers.end(), [](const std::string& solver) {
           return allocator_registry().find(solver).capabilities.has(Capability::optimal);
         });
}

bool any_acting(const std::vector<TableInstance>& instances) {
  return std::any_of(instances.begin(), instances.end(),
                     [](const TableInstance& instance) { return instance.problem.acting() == Acting::concurrent; });
}

std::vector<std::string> columns_of(const TableOptions& options, const std::vector<TableInstance>& instances) {
  return options.solvers.empty() ? default_table_solvers(any_acting(instances)) : options.solvers;
}

// The optimum of a plan-first row: the layered solver, past the state cap a certified interval
// (the whole tree's frontier, and a split of it where its first actions differ) whose lower end
// is raised to the row's best exact value (every policy's value is at most the optimum).
ExactPart optimum_of(const Mdp& mdp, const TableRow& row, std::size_t max_states, const TableOptions& options) {
  LayeredSolveOptions layered = options.layered;
  layered.max_states = max_states;
  layered.split = SplitMode::fallback;
  layered.ranks = options.ranks;
  layered.threads = options.threads;
  fill_default_caps(layered);
  const LayeredSolution solution = solve_layered(mdp, layered);
  ExactPart optimum;
  optimum.states = solution.states;
  optimum.cap_reached = !solution.exact;
  if (solution.exact) {
    optimum.value = solution.lower;
  } else {
    optimum.lower = solution.lower;
    for (const TableCell& cell : row.cells) {
      if (cell.exact && cell.exact->value) optimum.lower = std::max(*optimum.lower, *cell.exact->value);
    }
    optimum.upper = solution.upper;
  }
  return optimum;
}

// The optimum of a row acting while planning: the memoised solver of SPEC §10; past the cap, the
// interval from the row's best exact value (a policy's, at most the optimum) to 1.
ExactPart optimum_of(const ConcurrentMdp& mdp, const TableRow& row, std::size_t max_states,
                     const TableOptions& options) {
  ConcurrentSolver solver(mdp, max_states);
  solver.set_stop(options.stop);
  ExactPart optimum = exact_part(max_states, [&] {
    const double value = solver.solve(mdp.start());
    return std::pair{value, solver.states()};
  });
  if (optimum.cap_reached) {
    optimum.lower = 0.0;
    for (const TableCell& cell : row.cells) {
      if (cell.exact && cell.exact->value) optimum.lower = std::max(*optimum.lower, *cell.exact->value);
    }
    optimum.upper = 1.0;
  }
  return optimum;
}

// One row: every column's Monte Carlo run and, with exact parts, their exact values and the
// optimum. `factories` are the columns' allocators for this row's instance.
// (`Model`: Mdp, or ConcurrentMdp for a row acting while planning; `Factory` its allocators'.)
template <class Model, class Factory>
TableRow measure_row(const TableInstance& instance, const Model& mdp, const std::vector<std::string>& solvers,
                     const std::vector<Factory>& factories, std::size_t max_states, const TableOptions& options,
                     const std::function<void(std::uint64_t)>& progress) {
  TableRow row;
  row.source = instance.source;
  row.label = instance.label;
  row.name = instance.problem.name();
  row.acting = instance.problem.acting();
  row.rewards = instance.problem.has_rewards();
  std::uint64_t finished = 0;
  for (std::size_t column = 0; column < solvers.size(); ++column) {
    MonteCarloOptions monte_carlo;
    monte_carlo.episodes = options.episodes;
    monte_carlo.seed = options.seed;
    monte_carlo.threads = options.threads;
    monte_carlo.ranks = options.ranks;
    monte_carlo.stop = options.stop;
    monte_carlo.progress = [&](std::uint64_t done, std::uint64_t) { progress(finished + done); };
    TableCell cell{run_monte_carlo(mdp, factories[column], monte_carlo), std::nullopt};
    finished += options.episodes;
    if (options.exact && allocator_registry().find(solvers[column]).capabilities.has(Capability::stationary)) {
      const auto allocator = factories[column]();
      cell.exact = exact_part(max_states, [&] {
        const ExactEvaluation evaluation = evaluate_exactly(mdp, *allocator, max_states, options.stop);
        // The objective: the expected reward, which is the success probability without rewards.
        return std::pair{evaluation.expected_reward, evaluation.states};
      });
    }
    row.cells.push_back(std::move(cell));
  }
  if (options.exact) {
    const auto started = std::chrono::steady_clock::now();
    ExactPart optimum = optimum_of(mdp, row, max_states, options);
    optimum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    row.optimum = optimum;
  }
  return row;
}

}  // namespace

std::vector<std::string> default_table_solvers(bool acting) {
  // The paper's columns and the heuristics beside them; yardsticks (the optimum, certified search)
  // only when asked for.
  std::vector<std::string> names =
      allocator_registry().names({}, {Capability::needs_policy, Capability::optimal, Capability::certified});
  if (acting) {
    std::erase_if(names,
                  [](const std::string& name) { return !allocator_registry().find(name).acts_while_planning(); });
  }
  return names;
}

void check_table_request(const std::vector<TableInstance>& instances, const TableOptions& options,
                         const ParameterSpelling& spelling) {
  const std::vector<std::string> solvers = columns_of(options, instances);
  const std::vector<std::string> known = allocator_registry().names();
  const std::string what = spell_parameter(spelling, "solvers");
  for (auto name = solvers.begin(); name != solvers.end(); ++name) {
    if (name->empty()) {
      throw UsageError(what + ": name " + std::to_string(name - solvers.begin() + 1) + " is empty (a stray comma?)");
    }
    if (std::find(known.begin(), known.end(), *name) == known.end()) throw unknown_name_error("solver", *name, known);
    if (std::find(solvers.begin(), name, *name) != name) {
      throw UsageError(what + ": '" + *name + "' is given twice (one column per allocator)");
    }
  }
  if (instances.empty()) throw UsageError("a table needs at least one instance");
  // An instance given twice (the same file under any name) would repeat its row.
  for (std::size_t i = 0; i < instances.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      std::error_code error;
      const bool same_file = instances[i].source == instances[j].source ||
                             std::filesystem::equivalent(instances[i].source, instances[j].source, error);
      if (same_file && instances[i].problem.acting() == instances[j].problem.acting()) {
        throw UsageError(instances[i].source + ": instance given twice (as argument " + std::to_string(j + 1) +
                         " and " + std::to_string(i + 1) + "); one row per instance and acting mode");
      }
    }
  }
  const bool exact_work = needs_exact_work(options, solvers);
  const std::uint64_t allocators = worker_count(options.episodes, options.threads);
  const std::vector<std::string> acting = allocator_registry().acting_names();
  for (const TableInstance& instance : instances) {
    if (exact_work) check_exact_work(instance.problem, max_states_of(instance.parameters), instance.source, spelling);
    if (instance.problem.acting() == Acting::concurrent) {
      const ConcurrentMdp checked(instance.problem);  // refuses what this mode does not model yet
      for (const std::string& solver : solvers) {
        if (std::find(acting.begin(), acting.end(), solver) == acting.end()) {
          throw UsageError(instance.source + ": allocator '" + solver +
                           "' does not act while planning (SPEC §10) yet: it has no commit rule; " +
                           fmt::format("{}", fmt::join(acting, ", ")) + " do");
        }
      }
    }
    for (const std::string& solver : solvers) {
      allocator_registry().check_memory(solver, instance.problem, instance.parameters, allocators, spelling);
    }
  }
}

Table measure_table(const std::vector<TableInstance>& instances, const TableOptions& options) {
  Table table;
  table.solvers = columns_of(options, instances);
  table.exact = options.exact;
  table.episodes = options.episodes;
  table.seed = options.seed;
  // Every column's allocators first (policies loaded, parameters checked): a bad value stops
  // the table before any long computation.
  // A row acting while planning (SPEC §10) has a ConcurrentMdp and its allocators' concurrent forms.
  std::vector<std::unique_ptr<Mdp>> mdps(instances.size());
  std::vector<std::unique_ptr<ConcurrentMdp>> concurrent_mdps(instances.size());
  std::vector<std::vector<AllocatorFactory>> factories(instances.size());
  std::vector<std::vector<ConcurrentAllocatorFactory>> concurrent_factories(instances.size());
  for (std::size_t i = 0; i < instances.size(); ++i) {
    table.max_states.push_back(max_states_of(instances[i].parameters));
    if (instances[i].problem.acting() == Acting::concurrent) {
      concurrent_mdps[i] = std::make_unique<ConcurrentMdp>(instances[i].problem);
      for (const std::string& solver : table.solvers) {
        concurrent_factories[i].push_back(
            make_concurrent_allocator_factory(solver, *concurrent_mdps[i], instances[i].parameters));
      }
      continue;
    }
    mdps[i] = std::make_unique<Mdp>(instances[i].problem);
    for (const std::string& solver : table.solvers) {
      factories[i].push_back(make_allocator_factory(solver, *mdps[i], instances[i].parameters));
    }
  }
  const std::uint64_t per_row = options.episodes * table.solvers.size();
  const std::uint64_t total = per_row * instances.size();
  for (std::size_t i = 0; i < instances.size(); ++i) {
    const auto progress = [&options, i, per_row, total](std::uint64_t done) {
      if (options.progress) options.progress(i * per_row + done, total);
    };
    table.rows.push_back(
        concurrent_mdps[i]
            ? measure_row(instances[i], *concurrent_mdps[i], table.solvers, concurrent_factories[i],
                          table.max_states[i], options, progress)
            : measure_row(instances[i], *mdps[i], table.solvers, factories[i], table.max_states[i], options, progress));
  }
  return table;
}

}  // namespace ontime
