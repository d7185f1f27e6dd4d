#pragma once
// Runs the project's Python plotting scripts (python/*.py) with Debian's /usr/bin/python3,
// which has python3-matplotlib (scripts/setup.sh installs it). Plots are drawn from the CSV
// files the commands write, so a missing plotting stack never loses the data.
//
// The script draws into a private temporary directory; the drawing is moved onto the output
// only after the script succeeded, so a failure or an interruption leaves no partial output.
// The child runs in its own process group: SIGINT, SIGTERM and SIGHUP received by ontime are
// forwarded to it, ontime waits for it, removes the temporary directory and then dies of the
// same signal (exit status 130, 143, 129).

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace ontime::cli {

// The directory holding the scripts: $ONTIME_PYTHON_DIR, else share/ontime/python installed
// beside this executable, else the source tree's python/ (running from a build tree).
std::string python_script_directory();

// The exit status by which a script says its input data was bad (sysexits' EX_DATAERR); any
// other failure is a defect of the script or of the way it was called.
inline constexpr int kScriptBadInputExit = 65;

// `text` cut to at most `max_characters` UTF-8 characters, an ellipsis marking the cut: labels
// and titles are drawn and passed on command lines (each argument is limited to 128 KiB).
std::string shortened_label(std::string_view text, std::size_t max_characters);

// Runs `python3 DIR/script arguments(drawing)...`, where `drawing` is the path the script must
// write its figure to; on success the figure is written to `output`. Failures are reported with
// the last line the script wrote on stderr: ontime::InputError when the script exits with
// kScriptBadInputExit, std::runtime_error otherwise. ontime::UsageError when the interpreter
// ($ONTIME_PYTHON, default /usr/bin/python3) is missing or no temporary folder ($TMPDIR) can be used.
void run_python_script(const std::string& script, const std::filesystem::path& output,
                       const std::function<std::vector<std::string>(const std::string& drawing)>& arguments);

}  // namespace ontime::cli
