#pragma once
// Runs a command (no shell) and captures its exit code, stdout and stderr.

#include <string>
#include <vector>

namespace ontime::testing {

struct ProcessResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

ProcessResult run_process(const std::vector<std::string>& arguments);

}  // namespace ontime::testing
