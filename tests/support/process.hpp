#pragma once
// Runs a command (no shell) and captures its exit code, stdout and stderr.

#include <functional>
#include <string>
#include <vector>

namespace ontime::testing {

struct ProcessResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// With interrupt_after_ms >= 0, sends SIGINT to the command after that many milliseconds.
ProcessResult run_process(const std::vector<std::string>& arguments, int interrupt_after_ms = -1);

// Sends `signal_number` (SIGINT unless given) to the command as soon as `interrupt_when()` holds
// (asked every 5 ms while the command runs), at most once.
ProcessResult run_process(const std::vector<std::string>& arguments, const std::function<bool()>& interrupt_when,
                          int signal_number = 2 /* SIGINT */);

}  // namespace ontime::testing
