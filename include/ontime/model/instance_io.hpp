#pragma once
// Reading and writing instance files (SPEC §5).
//
// Every rule of SPEC §1 and §5 is checked while reading. A violation raises InputError with
// the file, the JSON path of the offending value (e.g. `actions.a3.planning.pmf."0"`, or
// `line 3, column 5` for malformed JSON) and the rule.

#include <filesystem>
#include <string>
#include <string_view>

#include "ontime/model/problem.hpp"

namespace ontime {

// Reads and validates an instance file. Throws InputError.
Problem load_problem(const std::filesystem::path& path);

// Validates instance text; `source` names it in error messages. Throws InputError.
Problem parse_problem(std::string_view text, std::string_view source);

// The instance as JSON text (PMF form, sorted keys), readable back by parse_problem.
std::string problem_to_json(const Problem& problem);

// Writes problem_to_json atomically: a temporary file beside `path`, then a rename, so a
// reader sees the old file or the complete new one.
void save_problem(const Problem& problem, const std::filesystem::path& path);

}  // namespace ontime
