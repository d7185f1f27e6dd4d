#pragma once
// The memory this process can have, and the check that a cap fits in it before long work
// starts: a cap the machine cannot honour would end in "out of memory" (the process killed, or
// exit 1) instead of the cap's own clean stop, so it is refused up front as a usage error.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace ontime {

// The smaller of /proc/meminfo's MemAvailable and the room left under this process's cgroup
// memory limit (v2 memory.max, or v1 memory.limit_in_bytes); nothing when neither is readable.
std::optional<std::uint64_t> available_memory_bytes();

// Throws UsageError "WHAT: would need up to N GiB of memory, M GiB available" when `bytes`
// exceed the available memory (nothing when it cannot be read).
void check_memory_for(std::string_view what, double bytes);

// How a caller writes a parameter in its messages: the command line as "--max-states", Python
// as "max_states". Null: "parameter 'max-states'".
using ParameterSpelling = std::function<std::string(std::string_view parameter)>;
std::string spell_parameter(const ParameterSpelling& spelling, std::string_view parameter);

}  // namespace ontime
