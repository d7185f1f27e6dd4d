#pragma once
// One report of every result: its JSON, for programs (the command line's --json, and the dicts
// that Python's functions return, which are this JSON read back), and its text, for people (the
// command line's readable output). The command line prints these and Python parses the same JSON,
// so the two give the same fields and the same numbers by construction.
//
// JSON is two-space indented, without a final newline; every double is written so that reading
// it back gives the same double. Fields a report leaves out when asked for no timing (seconds,
// latencies, peak memory) are the ones that depend on the machine, so that the rest can be
// compared byte for byte.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/learn/fitting.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/experiments.hpp"
#include "ontime/run/regret.hpp"
#include "ontime/run/table.hpp"
#include "ontime/solve/concurrent_search.hpp"
#include "ontime/solve/layered_solver.hpp"
#include "ontime/solve/search_solver.hpp"

namespace ontime::report {

// The parameters `kind` declares, given or defaulted, as a JSON object of text values.
std::string parameters_json(const AllocatorKind& kind, const ParameterValues& values);

// A Monte Carlo evaluation of one allocator, with its exact value when computed.
struct Evaluation {
  std::string solver = {};
  ParameterValues parameters = {};
  std::string instance = {};  // where the instance came from, as given
  const Problem* problem = nullptr;
  std::string belief = {};  // the instance the allocator planned with, when not `instance`
  std::uint64_t seed = 0;
  MonteCarloResult result = {};
  std::optional<ExactEvaluation> exact = {};
  std::optional<RegretEstimate> regret = {};  // with_regret's estimate of V* - V^pi
  bool timing = true;                         // decision times and run time
};
// Its JSON (`ontime evaluate --json`): the solver and its parameters, the instance, the Monte Carlo result and
// the exact value when computed.
std::string to_json(const Evaluation& evaluation);
// Its text (`ontime evaluate`): the same for people.
std::string to_text(const Evaluation& evaluation);

// The exact optimum or a certified interval (the layered solver), or the memoised solver's
// optimum (`memoised`: method "memoised", no layers, no interval).
struct Solve {
  std::string instance = {};
  const Problem* problem = nullptr;
  const Mdp* mdp = nullptr;
  std::string method = "layered";
  LayeredSolution solution = {};
  bool memoised = false;
  // The branch-and-bound search's solution (method "search"), in place of `solution`.
  std::optional<SearchSolution> search = std::nullopt;
  double tolerance = 0;
  double seconds = 0;
  bool timing = true;
  bool stats = false;  // states (and times) per layer
};
// Its JSON (`ontime solve --json`): the instance, the method, the optimum or its bounds, the first choice, and the
// states per layer when `stats`.
std::string to_json(const Solve& solve);
// Its text (`ontime solve`): the same for people.
std::string to_text(const Solve& solve);
// The policy of the first layers (LayeredSolveOptions::policy_layers): one JSON line per state,
// its choice and the bounds of its value.
std::string policy_lines(const Solve& solve);

// The optimum of acting while planning (SPEC §10, solve_concurrent): its value (or a certified
// interval where a cap, a stop or a gap ended the search), the first move (always a refinement:
// nothing is refined at the start), the states solved.
struct ConcurrentSolve {
  std::string instance = {};
  const Problem* problem = nullptr;
  std::string method = "memoised";  // or "search", "layered"
  ConcurrentSolution solution = {};
  double seconds = 0;
  bool timing = true;
  bool stats = false;  // layered: states (and, with timing, seconds) per level
};
// Its JSON (`ontime solve --act concurrent --json`): the memoised solve's keys and "acting".
std::string to_json(const ConcurrentSolve& solve);
// Its text: the instance, the acting mode, the optimum, the first choice, the states.
std::string to_text(const ConcurrentSolve& solve);

// Table I's layout (run/table.hpp).
std::string to_json(const Table& table);
// A heading line, the Markdown table (one row per instance, the mean decision time of each
// column last) and, with exact parts, the states and seconds of each.
// `spelling` names the state cap as the caller writes it ("--max-states").
std::string to_markdown(const Table& table, const ParameterSpelling& spelling = nullptr);

// A ppo training (learn/ppo_training.hpp) and the exact value of the policy it trained (greedy),
// when the instance is narrow enough for exact evaluation.
struct Training {
  std::string instance = {};
  const Problem* problem = nullptr;
  std::string policy = {};              // the policy file written
  std::vector<std::string> files = {};  // every file written, the policy first
  std::uint64_t episodes = 0, seed = 0;
  std::size_t epochs = 0;
  double seconds = 0;
  std::optional<double> exact = {};
  std::optional<double> exact_reward = {};  // the expected reward too, for an instance with rewards (SPEC §8)
};
// Its JSON (`ontime train --json`): the instance, the files written, the training's size and the exact value.
std::string to_json(const Training& training);
// Its text (`ontime train`): the same for people.
std::string to_text(const Training& training);

// A study (run/experiments.hpp) as the CSV that python/plot_study.py draws: compute-time, one
// row per instance and allocator; equal-time, one per instance; anytime, one per instance and
// multiplier.
std::string study_csv(const StudyRows& rows, const StudySettings& settings);

// The allocator kinds of a registry with their capabilities and parameters: JSON (a list of
// kinds), and Markdown (a table of kinds, then one of parameters, each named as `spelling` writes
// it: "--max-states" on the command line).
std::string registry_json(const AllocatorRegistry& registry);
std::string registry_markdown(const AllocatorRegistry& registry, const ParameterSpelling& spelling = nullptr);

// What a planner log held about each action and the distributions fitted from it (learn/fitting.hpp).
std::string fit_json(const FitResult& fit);
std::string fit_markdown(const FitResult& fit);

// Every action's planning and execution PMF as CSV (action,distribution,step,probability): one
// row per step with positive mass, then "never" (python/plot_histograms.py draws it).
std::string histogram_csv(const Problem& problem);

// A CSV field quoted ("a ""b"""), so that any text stands in one field.
std::string csv_field(std::string_view text);

// A Markdown table: a header row, the rule below it and the body rows, columns padded to their
// display width; cells may hold UTF-8 ("±", "µ", "≤").
std::string markdown_table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& body);

}  // namespace ontime::report
