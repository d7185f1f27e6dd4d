#pragma once
// Memory caps checked against the memory this process can have, before long work starts: a
// cap the machine cannot honour would end in "out of memory" (exit 1) instead of the cap's own
// clean stop, so it is refused as a usage error (exit 2) naming the option and the bytes.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "ontime/model/problem.hpp"
#include "ontime/solve/layered_solver.hpp"

namespace ontime::cli {

// The smaller of /proc/meminfo's MemAvailable and the room left under this process's cgroup
// memory limit (v2 memory.max, or v1 memory.limit_in_bytes); nothing when neither is readable.
std::optional<std::uint64_t> available_memory_bytes();

// Throws UsageError "OPTION: would need up to N GiB of memory, M GiB available" when `bytes`
// exceeds the available memory.
void check_memory_for(std::string_view option, double bytes);

// Checks, before exact work on `problem` (read from `source`) starts, that the exact solver and
// the exact evaluation take it: InputError naming the source when it has more skeletons than
// kMaxExactSkeletons; UsageError as above when their state cap could need more memory than is
// available (the table's slot per state, optimal.hpp, doubled by its power-of-two growth and by
// 1.5 while it grows, is the most they can hold before the cap stops them).
void check_state_cap_memory(const Problem& problem, std::size_t max_states, const std::string& source);

// The layered solver as the tool runs it (solve, table --exact). Fills in the memory and disk
// caps that are still 0: 80% of the available memory divided among the job's ranks, and 90% of
// the free space where the scratch files go, so that it stops with a certified interval rather
// than being killed or filling the disk. Removes the scratch on SIGINT, SIGTERM and SIGHUP, and
// says so on standard error (as it does for each directory a killed run left behind).
void apply_tool_layered_settings(LayeredSolveOptions& options);

}  // namespace ontime::cli
