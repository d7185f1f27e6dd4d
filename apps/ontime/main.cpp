// The `ontime` command-line tool: parses arguments, calls the library, prints.
// Exit codes: 0 success, 2 bad input or usage (message names the file, the place, the rule),
// 1 internal error.

#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <memory>
#include <new>
#include <string>
#include <utility>

#include "cluster_job.hpp"
#include "common.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"

namespace {

constexpr int kUsageExit = 2;
constexpr int kInternalExit = 1;

// Runs the command line and returns the exit code, with the message to print, if any.
std::pair<int, std::string> run(int& argc, char**& argv) {
  const auto failure = [](const char* kind, const char* message, int code) {
    return std::pair<int, std::string>{code, fmt::format("ontime: {}: {}", kind, message)};
  };
  try {
    // An MPI launcher's process joins its job first: rank 0 alone prints, and errors are
    // reported once (cluster_job.hpp).
    ontime::cli::join_cluster_job(argc, argv);
    const std::unique_ptr<CLI::App> application = ontime::cli::make_app();
    CLI::App& app = *application;
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
      if (error.get_exit_code() == 0) {  // --help, --version
        if (ontime::cli::is_job_root()) return {app.exit(error), std::string()};
        return {0, std::string()};
      }
      return {kUsageExit,
              fmt::format("ontime: usage error: {} (see 'ontime --help' or 'ontime COMMAND --help')", error.what())};
    }
  } catch (const ontime::InputError& error) {
    return failure("error", error.what(), kUsageExit);
  } catch (const ontime::UsageError& error) {
    return failure("usage error", error.what(), kUsageExit);
  } catch (const ontime::ResourceLimitError& error) {
    return failure("resource limit", error.what(), kUsageExit);
  } catch (const std::bad_alloc&) {
    return failure("internal error", "out of memory", kInternalExit);
  } catch (const std::exception& error) {
    return failure("internal error", error.what(), kInternalExit);
  }
  return {0, std::string()};
}

}  // namespace

int main(int argc, char** argv) {
  // An interrupted command leaves no temporary file of an output behind (util/atomic_file.hpp).
  ontime::remove_temporaries_on_signal(true);
  const auto [code, message] = run(argc, argv);
  return ontime::cli::leave_cluster_job(code, message.empty() ? nullptr : message.c_str());
}
