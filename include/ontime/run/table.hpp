#pragma once
// Table I's layout as a computation: one row per instance, one column per allocator (sampled
// success ± 95% and, for stationary allocators, the exact value), the exact optimum of each
// row, and each allocator's decision time. The command line's `table` and Python's
// `ontime.table` run this; report/report.hpp writes it as JSON or as a Markdown table.
//
// Guarantees: the sampled cells are run_monte_carlo's (episode i of every column lives in the
// world of stream i of the seed: common random numbers across columns); an exact part that
// would need more than the state cap is reported as reached in its cell, so that one large
// instance does not cost the whole table. The optimum comes from the layered solver: exact, or
// past its caps a certified interval whose lower end is raised to the row's best exact value
// (every policy's value is at most the optimum).
//
// Cost: per row, episodes x columns episodes, plus the exact parts (linear in the states each
// reaches, up to the cap).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/solve/layered_solver.hpp"

namespace ontime {

// An exact computation: its value, or the cap it reached (and then, for the optimum, the
// certified interval); its states and seconds.
struct ExactPart {
  std::optional<double> value;
  bool cap_reached = false;
  std::size_t states = 0;  // memoised states; at the cap: the cap
  std::optional<double> lower, upper;
  double seconds = 0;
};

struct TableCell {
  MonteCarloResult sampled;
  std::optional<ExactPart> exact;  // with exact parts, for stationary allocators
};

struct TableRow {
  std::string label;                   // the instance's file stem, or the name given
  std::string source;                  // where the instance came from (a file), as given
  std::string name;                    // the instance's own name
  Acting acting = Acting::plan_first;  // the instance's mode (SPEC §10)
  // The instance has rewards (SPEC §8): the exact parts are expected rewards, and the report
  // shows the mean reward beside the success rate.
  bool rewards = false;
  std::vector<TableCell> cells;  // one per column
  std::optional<ExactPart> optimum;
};

// An instance whose acting is concurrent (SPEC §10) is a row acting while planning: its columns are
// the allocators' concurrent forms (each kind's commit rule), its exact values the solver's policy
// mode, and its optimum the memoised solver of that model (past the state cap, the interval from
// the row's best exact value to 1). The same file may then come twice, once in each mode.
struct TableInstance {
  Problem problem;
  std::string source;          // a file, for messages and the report
  std::string label;           // the row's label
  ParameterValues parameters;  // the columns' parameters for this row (policies differ per instance)
};

struct TableOptions {
  std::vector<std::string> solvers;  // the columns; empty: default_table_solvers()
  bool exact = false;                // exact values and the exact optimum
  std::uint64_t episodes = 10'000;
  std::uint64_t seed = 1;
  unsigned threads = 0;
  const Ranks* ranks = nullptr;
  // The optimum's solver settings: caps still 0 get fill_default_caps's; max_states, ranks and
  // threads are the table's.
  LayeredSolveOptions layered;
  // Called with the episodes done over the whole table and their total.
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
  // Checked before each episode and every few thousand exact states: the table ends by throwing
  // Cancelled once it returns true.
  std::function<bool()> stop;
};

struct Table {
  std::vector<std::string> solvers;
  bool exact = false;
  std::uint64_t episodes = 0, seed = 0;
  std::vector<std::size_t> max_states;  // each row's state cap (the max-states parameter)
  std::vector<TableRow> rows;
};

// The default columns: every allocator that needs nothing beyond the instance, the optimum
// (its own column with exact parts) aside; with `acting`, only those with a commit rule.
std::vector<std::string> default_table_solvers(bool acting = false);

// Checks everything that can be checked before the long work, so that a bad request stops the
// table at once: UsageError for no column, an empty, unknown or repeated name, an instance given
// twice (the same file under any name), a parameter that breaks its declaration or memory the
// columns could not hold (`spelling` names parameters in messages); InputError for an instance
// the exact parts cannot take.
void check_table_request(const std::vector<TableInstance>& instances, const TableOptions& options,
                         const ParameterSpelling& spelling = nullptr);

// Runs the table (after check_table_request). Throws Cancelled when `options.stop` trips.
Table measure_table(const std::vector<TableInstance>& instances, const TableOptions& options);

}  // namespace ontime
