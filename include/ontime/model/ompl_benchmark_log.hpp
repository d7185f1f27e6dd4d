#pragma once
// OMPL benchmark logs (docs/formats.md): the `.log` text files written by OMPL's benchmarking
// tool (ompl::tools::Benchmark), read as refinement attempts and written from them. No OMPL is
// needed: the format is plain text.
//
// Reading. Each run of each planner becomes one RefinementAttempt: its planning time is the run
// property `time REAL`; it found a motion when `solved BOOLEAN` is 1 and the time is within the
// experiment's time limit (`T seconds per run`). Any other run was cut off and is censored at the
// time limit. The execution time of a found motion is its `solution length REAL` divided by a
// speed (path-length units per second) the caller gives. The optional run properties
// `trial INTEGER` and `collision checks INTEGER` fill the attempt's trial and collision checks.
// The action of a planner's runs is a fixed action, the first matching rule of a mapping, or
// (neither given) the planner's name. Every rule is checked; a broken one raises InputError
// naming the file, the line (and run property) and the rule.
//
// Writing. One experiment; one "planner" per action (named by the action id, in order of first
// appearance), one run per attempt with the properties above; the time limit is the caller's
// cut-off. Read back with speed 1 and no mapping, it gives the attempts again, cut-off attempts
// censored at the time limit.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/model/planner_log.hpp"

namespace ontime {

// One rule of an action mapping: it matches a planner of an experiment when every name it gives
// equals (at least one of the two is given).
struct OmplActionRule {
  std::optional<std::string> experiment;
  std::optional<std::string> planner;
  std::string action;  // non-empty

  friend bool operator==(const OmplActionRule&, const OmplActionRule&) = default;
};

// A mapping file (docs/formats.md): {"rules": [{"experiment": ..., "planner": ..., "action": ...}]}.
// The first rule that matches names the action.
struct OmplActionMapping {
  std::string source;  // the file, for messages
  std::vector<OmplActionRule> rules;
};

// Throws InputError (unreadable file, invalid JSON, a rule broken).
OmplActionMapping load_ompl_action_mapping(const std::filesystem::path& path);
OmplActionMapping parse_ompl_action_mapping(std::string_view text, std::string_view source);

struct OmplLogReadOptions {
  double speed = 1.0;                          // path-length units per second of execution; finite, > 0
  std::string action;                          // when non-empty: every run of the log is of this action
  const OmplActionMapping* mapping = nullptr;  // else, when set: the planner's action by the mapping
};

// What a log holds, as refinement attempts (planner by planner, run by run).
struct OmplBenchmarkRuns {
  std::string experiment;
  double time_limit_seconds = 0;
  std::vector<RefinementAttempt> attempts;
};

// Throws InputError (unreadable file, a rule of the format broken, no run, a planner no rule of
// the mapping matches) and UsageError for bad options (a speed that is not positive).
OmplBenchmarkRuns load_ompl_benchmark_log(const std::filesystem::path& path, const OmplLogReadOptions& options);
OmplBenchmarkRuns parse_ompl_benchmark_log(std::string_view text, std::string_view source,
                                           const OmplLogReadOptions& options);

struct OmplLogWriteOptions {
  std::string experiment = "ontime";  // the experiment's name: one line, non-empty
  double time_limit_seconds = 0;      // the cut-off of the attempts; finite, > 0
  std::string setup;                  // free text for the setup block (how the attempts were made)
  std::uint64_t seed = 0;             // the random seed line
};

// The log text. Throws UsageError for bad options or an action id that cannot be one line of the
// log (a line break in it, or a carriage return at its end).
std::string ompl_benchmark_log_text(std::span<const RefinementAttempt> attempts, const OmplLogWriteOptions& options);

// Writes the log atomically (temporary file, then rename).
void save_ompl_benchmark_log(std::span<const RefinementAttempt> attempts, const std::filesystem::path& path,
                             const OmplLogWriteOptions& options);

}  // namespace ontime
