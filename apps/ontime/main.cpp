// The `ontime` command-line tool: parses arguments, calls the library, prints.
// Exit codes: 0 success, 2 bad input or usage (message names the file, the place, the rule),
// 1 internal error.

#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <memory>
#include <new>

#include "common.hpp"
#include "ontime/error.hpp"

namespace {

constexpr int kUsageExit = 2;
constexpr int kInternalExit = 1;

int report(const char* kind, const char* message, int code) {
  fmt::print(stderr, "ontime: {}: {}\n", kind, message);
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  const std::unique_ptr<CLI::App> application = ontime::cli::make_app();
  CLI::App& app = *application;

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);  // --help, --version
    fmt::print(stderr, "ontime: usage error: {} (see 'ontime --help' or 'ontime COMMAND --help')\n", error.what());
    return kUsageExit;
  } catch (const ontime::InputError& error) {
    return report("error", error.what(), kUsageExit);
  } catch (const ontime::UsageError& error) {
    return report("usage error", error.what(), kUsageExit);
  } catch (const ontime::ResourceLimitError& error) {
    return report("resource limit", error.what(), kUsageExit);
  } catch (const std::bad_alloc&) {
    return report("internal error", "out of memory", kInternalExit);
  } catch (const std::exception& error) {
    return report("internal error", error.what(), kInternalExit);
  }
  return 0;
}
