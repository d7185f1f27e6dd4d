#pragma once
// The invalid OMPL benchmark logs of tests/data/bad_ompl_logs (each a copy of
// tests/data/ompl_logs/kitchen.log with one rule broken), with the place and rule each must report.

#include <array>

#include "support/bad_inputs.hpp"

namespace ontime::testing {

inline const std::array kBadOmplLogs{
    BadInput{"not_a_log.log", "line 1", "expected 'Experiment NAME'"},
    BadInput{"empty.log", "end of file", "the file ends where the experiment's name belongs"},
    BadInput{"time_limit_missing.log", "line 15", "expected the time limit"},
    BadInput{"time_limit_zero.log", "line 15", "finite number of seconds > 0"},
    BadInput{"shared_run_budget.log", "line 17", "0 runs per planner"},
    BadInput{"block_unclosed.log", "line 11", "never closed by '|>>>'"},
    BadInput{"planners_too_many.log", "end of file", "the file ends where a planner's name belongs"},
    BadInput{"planners_too_few.log", "line 37", "text after the last of the 1 planners"},
    BadInput{"runs_too_many.log", "line 36", "must each end with ';'"},
    BadInput{"runs_too_few.log", "line 35", "expected '.' after the 2 runs"},
    BadInput{"runs_count_not_number.log", "line 32", "N must be a whole number >= 0"},
    BadInput{"values_too_few.log", "line 34", "a run has 4 values, the planner announces 5 properties"},
    BadInput{"time_not_number.log", "line 35: time REAL", "must be a number of seconds"},
    BadInput{"time_negative.log", "line 45: time REAL", "finite number of seconds >= 0"},
    BadInput{"time_nan.log", "line 45: time REAL", "finite number of seconds >= 0"},
    BadInput{"solved_not_boolean.log", "line 33: solved BOOLEAN", "must be 0 or 1"},
    BadInput{"length_missing.log", "line 33: solution length REAL", "finite number >= 0"},
    BadInput{"length_infinite.log", "line 47: solution length REAL", "finite number >= 0"},
    BadInput{"no_time_property.log", "line 26", "no property 'time REAL'"},
    BadInput{"property_twice.log", "line 30", "listed twice"},
    BadInput{"no_runs.log", "file", "the log holds no runs"},
};

}  // namespace ontime::testing
