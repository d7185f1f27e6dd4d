#pragma once
// The command line's spelling of the library's memory checks (util/memory.hpp, the registry's
// check_memory, check_exact_work): parameters named as flags, and the layered solver run as the
// tool runs it.

#include <cstdint>

#include "ontime/solve/layered_solver.hpp"
#include "ontime/util/memory.hpp"

namespace ontime::cli {

// Parameters as the command line writes them: "--max-states".
ParameterSpelling flag_spelling();

// The layered solver as the tool runs it (solve, table --exact): the library's default caps
// (fill_default_caps), the scratch removed on SIGINT, SIGTERM and SIGHUP, and a line on standard
// error for each directory a killed run left behind.
void apply_tool_layered_settings(LayeredSolveOptions& options);

}  // namespace ontime::cli
