#pragma once
// The largest --threads a command accepts. Far above any machine this runs on, and low enough
// that the system can always start that many threads, so that a mistyped count is a usage
// error naming the option instead of a failure to start a thread in the middle of the work.

namespace ontime::cli {

inline constexpr unsigned kMaxThreads = 1024;

}  // namespace ontime::cli
