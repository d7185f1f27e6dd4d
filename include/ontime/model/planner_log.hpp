#pragma once
// Planner logs (docs/formats.md): what a motion planner reports about its attempts to refine
// abstract actions, the data the time distributions are learned from (paper §V).
//
// A log is JSON Lines: one JSON object per line, one line per attempt to refine one action:
//
//   {"action": "move(R1,R5)", "planning_seconds": 1.62, "found": true, "execution_seconds": 5.3}
//   {"action": "move(R5,R8)", "planning_seconds": 44.0, "found": false}
//
// Records may also name their world and carry the action's feature vector there (a corpus
// across worlds for conditional time models): "world": "building-s7", "features": [0.92, ...].
//
// `found: false` means the attempt was cut off after `planning_seconds` of effort without a
// motion (right-censored: its planning time is known only to exceed that), unless the record says
// "backtrack": "ACTION ID": the refiner gave up then and blamed that earlier action (SPEC §7). Reading checks
// every rule and raises InputError naming the file, the line (and key) and the rule.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace ontime {

struct RefinementAttempt {
  std::string action;                             // abstract action id, non-empty
  double planning_seconds = 0;                    // effort spent, finite, >= 0
  bool found = false;                             // a motion was found; false: cut off (censored)
  double execution_seconds = 0;                   // time to execute the motion; only when found
  std::optional<std::uint64_t> trial;             // optional: the collection trial it belongs to
  std::optional<std::uint64_t> collision_checks;  // optional: deterministic effort, if counted
  // Optional, for conditional time models (docs/formats.md): the world the attempt was made in
  // and the action's feature vector there (finite numbers, the same length in every record of
  // a log that has them).
  std::optional<std::string> world;
  std::vector<double> features;
  // Optional, backtracking (SPEC §7): the attempt gave up after `planning_seconds` and blamed
  // this earlier action (found is false; an event, not a cut-off).
  std::optional<std::string> backtrack;

  friend bool operator==(const RefinementAttempt&, const RefinementAttempt&) = default;
};

// Throws InputError (file missing or unreadable, a line that breaks a rule, no records).
std::vector<RefinementAttempt> load_planner_log(const std::filesystem::path& path);
std::vector<RefinementAttempt> parse_planner_log(std::string_view text, std::string_view source);

// One record as a JSON line (with its newline); parse_planner_log reads it back exactly.
std::string planner_log_line(const RefinementAttempt& attempt);

// Writes the records atomically (temporary file, then rename).
void save_planner_log(std::span<const RefinementAttempt> attempts, const std::filesystem::path& path);

}  // namespace ontime
