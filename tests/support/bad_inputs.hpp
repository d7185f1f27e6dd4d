#pragma once
// The invalid instance files of tests/data/bad, with the place and rule each must report.

#include <array>
#include <string>

namespace ontime::testing {

struct BadInput {
  std::string file;
  std::string place;
  std::string rule;  // a fragment of the rule text
};

inline const std::array kBadInputs{
    BadInput{"not_json.json", "line 7, column 1", "invalid JSON"},
    BadInput{"empty.json", "line 1, column 1", "invalid JSON"},
    BadInput{"nan_probability.json", "line 4, column 38", "invalid JSON"},
    BadInput{"trailing_garbage.json", "line 1, column 128", "expected end of input"},
    BadInput{"number_overflow.json", "line 4, column 38", "number overflow"},
    BadInput{"duplicate_key.json", "actions.a1.planning.pmf.\"1\"", "duplicate key"},
    BadInput{"top_level_array.json", "top level", "must be a JSON object"},
    BadInput{"unknown_top_key.json", "deadlines", "unknown key"},
    BadInput{"name_not_string.json", "name", "must be a string"},
    BadInput{"acting_unknown.json", "acting", "must be \"plan-first\" or \"concurrent\" (got \"interleaved\")"},
    BadInput{"acting_not_string.json", "acting", "must be \"plan-first\" or \"concurrent\" (got a boolean)"},
    BadInput{"missing_deadline.json", "top level", "missing required key 'deadline'"},
    BadInput{"deadline_zero.json", "deadline", "between 1 and 10000"},
    BadInput{"deadline_too_large.json", "deadline", "between 1 and 10000"},
    BadInput{"deadline_fraction.json", "deadline", "whole number of steps"},
    BadInput{"deadline_string.json", "deadline", "whole number of steps"},
    BadInput{"step_seconds_negative.json", "step_seconds", "positive number of seconds"},
    BadInput{"missing_actions.json", "top level", "missing required key 'actions'"},
    BadInput{"actions_empty.json", "actions", "at least one action"},
    BadInput{"actions_not_object.json", "actions", "must be an object"},
    BadInput{"action_id_empty.json", "actions.\"\"", "non-empty"},
    BadInput{"action_missing_execution.json", "actions.a2", "missing required key 'execution'"},
    BadInput{"action_unknown_key.json", "actions.a2.cost", "unknown key"},
    BadInput{"distribution_both_forms.json", "actions.a2.planning", "exactly one of 'pmf' or 'cdf'"},
    BadInput{"distribution_no_form.json", "actions.a2.planning", "exactly one of 'pmf' or 'cdf'"},
    BadInput{"distribution_not_object.json", "actions.a2.planning", "must be an object"},
    BadInput{"pmf_not_object.json", "actions.a2.planning.pmf", "mapping steps to probabilities"},
    BadInput{"pmf_negative.json", "actions.a1.planning.pmf.\"1\"", "within [0, 1]"},
    BadInput{"pmf_above_one.json", "actions.a1.planning.pmf.\"1\"", "within [0, 1]"},
    BadInput{"pmf_sum_above_one.json", "actions.a1.planning.pmf", "sum to 1.2, above 1"},
    BadInput{"pmf_not_number.json", "actions.a1.planning.pmf.\"1\"", "must be a number"},
    BadInput{"pmf_key_not_integer.json", "actions.a1.planning.pmf.\"1.5\"", "whole numbers of steps"},
    BadInput{"pmf_key_negative.json", "actions.a1.execution.pmf.\"-1\"", "whole numbers of steps"},
    BadInput{"pmf_key_leading_zero.json", "actions.a1.planning.pmf.\"01\"", "leading zeros"},
    BadInput{"planning_step_zero.json", "actions.a3.planning.pmf.\"0\"", "planning steps start at 1"},
    BadInput{"step_too_large.json", "actions.a1.planning.pmf.\"100001\"", "steps above 100000"},
    BadInput{"cdf_decreasing.json", "actions.a3.planning.cdf.\"2\"", "must not decrease"},
    BadInput{"cdf_above_one.json", "actions.a3.planning.cdf.\"3\"", "within [0, 1]"},
    BadInput{"missing_skeletons.json", "top level", "missing required key 'skeletons'"},
    BadInput{"skeletons_empty.json", "skeletons", "at least one skeleton"},
    BadInput{"skeletons_not_array.json", "skeletons", "must be an array"},
    BadInput{"skeleton_empty.json", "skeletons[1]", "at least one action"},
    BadInput{"skeleton_not_array.json", "skeletons[1]", "must be an array of action ids"},
    BadInput{"action_id_not_string.json", "skeletons[1][1]", "must be a string"},
    BadInput{"skeleton_unknown_action.json", "skeletons[1][1]", "unknown action id 'a4'"},
    BadInput{"skeleton_repeated_action.json", "skeletons[0][2]", "appears twice in one skeleton"},
    BadInput{"skeleton_duplicate.json", "skeletons[2]", "the same skeleton as skeletons[0]"},
    BadInput{"sharing_other_position.json", "skeletons[1][1]", "at another position"},
    BadInput{"sharing_other_prefix.json", "skeletons[1][1]", "the actions before it differ"},
    BadInput{"skeleton_too_long.json", "skeletons[0]", "at most 255 actions"},
    // Backtracking (SPEC §7).
    BadInput{"culprit_after_failing_action.json", "actions.a.culprits.b", "the culprit comes after the failing action"},
    BadInput{"culprit_on_another_skeleton.json", "actions.b.culprits.c",
             "not before the action on its skeletons' path"},
    BadInput{"culprit_probability_above_one.json", "actions.b.culprits.a", "a probability must be within [0, 1]"},
    BadInput{"culprits_sum_above_one.json", "actions.c", "the culprits' probabilities sum to 1.250000, not 1"},
    BadInput{"backtrack_and_planning_above_one.json", "actions.b", "planning and backtrack probabilities sum above 1"},
    // Rewards (SPEC §8).
    BadInput{"rewards_not_array.json", "rewards", "must be an array with one reward per skeleton"},
    BadInput{"rewards_wrong_count.json", "rewards", "has 1 entries for 2 skeletons"},
    BadInput{"reward_above_one.json", "rewards[1]", "the value must be a number within [0, 1]"},
    BadInput{"reward_not_number.json", "rewards[0].value", "must be a number"},
    BadInput{"reward_negative_fall.json", "rewards[0]", "the fall per step must be a number of at least 0"},
    BadInput{"reward_below_zero_before_deadline.json", "rewards[1]", "falls below 0 before the deadline"},
    BadInput{"reward_unknown_key.json", "rewards[0].slope", "unknown key"},
    BadInput{"reward_missing_value.json", "rewards[0]", "missing required key 'value'"},
};

}  // namespace ontime::testing
