#pragma once
// Runs the project's Python plotting scripts (python/*.py) with Debian's /usr/bin/python3,
// which has python3-matplotlib (scripts/setup.sh installs it). Plots are drawn from the CSV
// files the commands write, so a missing plotting stack never loses the data.

#include <string>
#include <vector>

namespace ontime::cli {

// The directory holding the scripts: $ONTIME_PYTHON_DIR, else the source tree's python/ when
// running from a build tree, else the installed share/ontime/python.
std::string python_script_directory();

// Runs `python3 DIR/script arguments...`. Throws std::runtime_error with the script's error
// output when it fails or the interpreter ($ONTIME_PYTHON, default /usr/bin/python3) is missing.
void run_python_script(const std::string& script, const std::vector<std::string>& arguments);

}  // namespace ontime::cli
