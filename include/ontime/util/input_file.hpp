#pragma once
// The one reader of input files: every file the library reads (instances, policies, planner
// logs, skeleton files, world files) is read whole through read_input_file, which stops at a
// size limit so that a huge file or a device without end (/dev/zero, /dev/urandom, a FIFO fed
// forever) ends with an InputError naming the file and the limit instead of exhausting memory.
//
// The limit is 256 MiB by default; the environment variable ONTIME_MAX_INPUT_BYTES (a whole
// number of bytes) or set_max_input_bytes overrides it (docs/formats.md, docs/reliability.md).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace ontime {

inline constexpr std::uint64_t kDefaultMaxInputBytes = std::uint64_t{256} << 20;

// The limit in force: set_max_input_bytes's value if set, else ONTIME_MAX_INPUT_BYTES if set,
// else kDefaultMaxInputBytes. A malformed ONTIME_MAX_INPUT_BYTES raises UsageError.
std::uint64_t max_input_bytes();

// Overrides the limit for this process (std::nullopt: back to the environment or default).
void set_max_input_bytes(std::optional<std::uint64_t> bytes);

// The whole content of `path`. `what` names the kind of file in messages ("instance",
// "policy", "planner log", ...). Throws InputError for a directory, a file that cannot be
// opened or read, or one larger than max_input_bytes() (reading stops at the limit).
std::string read_input_file(const std::filesystem::path& path, std::string_view what);

}  // namespace ontime
