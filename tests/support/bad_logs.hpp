#pragma once
// The invalid planner logs of tests/data/bad_logs, with the place and rule each must report.

#include <array>

#include "support/bad_inputs.hpp"

namespace ontime::testing {

inline const std::array kBadLogs{
    BadInput{"not_json.jsonl", "line 2, column 42", "invalid JSON"},
    BadInput{"not_object.jsonl", "line 1", "a record must be a JSON object"},
    BadInput{"missing_action.jsonl", "line 1", "missing required key 'action'"},
    BadInput{"action_empty.jsonl", "line 1: action", "non-empty action id"},
    BadInput{"action_not_string.jsonl", "line 1: action", "must be a string"},
    BadInput{"planning_negative.jsonl", "line 3: planning_seconds", "finite number of seconds >= 0"},
    BadInput{"planning_not_number.jsonl", "line 1: planning_seconds", "must be a number of seconds"},
    BadInput{"planning_missing.jsonl", "line 1", "missing required key 'planning_seconds'"},
    BadInput{"found_not_boolean.jsonl", "line 1: found", "must be true or false"},
    BadInput{"found_without_execution.jsonl", "line 2", "missing required key 'execution_seconds'"},
    BadInput{"execution_when_not_found.jsonl", "line 1: execution_seconds", "only a found motion"},
    BadInput{"execution_negative.jsonl", "line 1: execution_seconds", "finite number of seconds >= 0"},
    BadInput{"unknown_key.jsonl", "line 1: planing_seconds", "unknown key"},
    BadInput{"duplicate_key.jsonl", "line 1: found", "duplicate key"},
    BadInput{"trial_negative.jsonl", "line 1: trial", "whole number >= 0"},
    BadInput{"checks_fraction.jsonl", "line 1: collision_checks", "whole number >= 0"},
    BadInput{"empty.jsonl", "file", "no records"},
    BadInput{"features_not_number.jsonl", "line 1: features[1]", "must be a finite number"},
    BadInput{"features_overflow.jsonl", "line 1, column 76", "number overflow"},
    BadInput{"features_empty.jsonl", "line 1: features", "non-empty array of numbers"},
    BadInput{"features_length.jsonl", "line 2: features", "has 1 numbers, but earlier records have 2"},
    BadInput{"world_empty.jsonl", "line 1: world", "non-empty string naming the world"},
    BadInput{"backtrack_found.jsonl", "line 1: backtrack", "found no motion ('found' must be false)"},
    BadInput{"backtrack_self.jsonl", "line 1: backtrack", "an action cannot blame itself"},
    BadInput{"backtrack_not_string.jsonl", "line 1: backtrack", "non-empty string naming the earlier action"},
};

}  // namespace ontime::testing
