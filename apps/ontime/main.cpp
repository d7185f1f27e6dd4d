// The `ontime` command-line tool: parses arguments, calls the library, prints.
// Exit codes: 0 success, 2 bad input or usage (message names the file, the place, the rule),
// 1 internal error. The domain commands (collect, map, run) exist only in the domains build
// (ONTIME_BUILD_DOMAINS, which needs OMPL, FCL and KDL); without it they are listed and refused.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <fmt/core.h>
#include <new>
#include <string>

#include "common.hpp"
#include "ontime/error.hpp"

namespace {

constexpr int kUsageExit = 2;
constexpr int kInternalExit = 1;

int report(const char* kind, const char* message, int code) {
  fmt::print(stderr, "ontime: {}: {}\n", kind, message);
  return code;
}

#if !ONTIME_WITH_DOMAINS
// A domain command in a build without the domains: listed in --help, refused with exit 2.
void add_unavailable_domain_command(CLI::App& app, const std::string& name) {
  CLI::App* command =
      app.add_subcommand(name, "(needs the domains build: this ontime was built with ONTIME_BUILD_DOMAINS=OFF)");
  command->allow_extras();
  command->callback([name] {
    throw ontime::UsageError("'" + name +
                             "' needs the domains build (OMPL, FCL, KDL): this ontime was built with "
                             "ONTIME_BUILD_DOMAINS=OFF");
  });
}
#endif

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("OnTime: deadline-aware effort allocation for task and motion planning.\n"
               "Decides, step by step, which plan skeleton gets the motion planner's next slice of effort.",
               "ontime");
  app.set_version_flag("--version", std::string("ontime ") + ONTIME_VERSION);
  app.require_subcommand(1);
  ontime::cli::add_solve_command(app);
  ontime::cli::add_evaluate_command(app);
  ontime::cli::add_table_command(app);
  ontime::cli::add_study_command(app);
  ontime::cli::add_train_command(app);
  ontime::cli::add_reduce_knapsack_command(app);
  ontime::cli::add_fit_command(app);
  ontime::cli::add_sample_log_command(app);
  ontime::cli::add_plot_command(app);
#if ONTIME_WITH_DOMAINS
  ontime::cli::add_collect_command(app);
  ontime::cli::add_map_command(app);
  ontime::cli::add_run_command(app);
#else
  for (const char* name : {"collect", "map", "run"}) add_unavailable_domain_command(app, name);
#endif

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);  // --help, --version
    fmt::print(stderr, "ontime: usage error: {}\nRun 'ontime --help' or 'ontime COMMAND --help'.\n", error.what());
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
