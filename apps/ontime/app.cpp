// The whole `ontime` command line: every command registered on one CLI::App. The domain
// commands (collect, map, run, tamp, generate-world, predict) exist only in the domains build
// (ONTIME_BUILD_DOMAINS, which needs OMPL, FCL and KDL); without it they are listed and refused.

#include <fmt/core.h>

#include <cstdio>
#include <mutex>
#include <set>
#include <string>
#include <utility>

#include "cluster_job.hpp"
#include "common.hpp"
#include "ontime/util/error.hpp"
#if ONTIME_WITH_DOMAINS
#include "ontime/domains/library_messages.hpp"
#endif

namespace ontime::cli {
namespace {

#if !ONTIME_WITH_DOMAINS
// A domain command in a build without the domains: listed in --help, refused with exit 2.
void add_unavailable_domain_command(CLI::App& app, const std::string& name) {
  CLI::App* command =
      app.add_subcommand(name, "(needs the domains build: this ontime was built with ONTIME_BUILD_DOMAINS=OFF)");
  // Whatever follows the name is this command's (it is refused as a whole): nothing falls through
  // to the top level, where it would be reported as unexpected arguments instead.
  command->allow_extras();
  command->fallthrough(false);
  command->callback([name] {
    throw UsageError("'" + name +
                     "' needs the domains build (OMPL, FCL, KDL): this ontime was built with "
                     "ONTIME_BUILD_DOMAINS=OFF");
  });
}
#endif

#if ONTIME_WITH_DOMAINS
// OMPL's and igraph's warnings and errors, each distinct one once, on the rank that prints: a
// collection plans thousands of motions, and one cause would otherwise repeat thousands of times.
void print_library_messages_once() {
  domains::set_library_message_sink(
      [](std::string_view library, domains::LibraryMessageLevel level, std::string_view text) {
        static std::mutex mutex;
        static std::set<std::pair<std::string, std::string>> printed;
        if (!is_job_root()) return;
        const std::lock_guard lock(mutex);
        if (!printed.emplace(std::string(library), std::string(text)).second) return;
        fmt::print(stderr, "ontime: {} {}: {}\n", library,
                   level == domains::LibraryMessageLevel::error ? "error" : "warning", text);
      });
}
#endif

}  // namespace

std::unique_ptr<CLI::App> make_app() {
  auto app = std::make_unique<CLI::App>(
      "OnTime: deadline-aware effort allocation for task and motion planning.\n"
      "Decides, step by step, which plan skeleton gets the motion planner's next slice of effort.",
      "ontime");
  app->set_version_flag("--version", std::string("ontime ") + ONTIME_VERSION);
  app->require_subcommand(1);
  // --quiet belongs to every command: given after the command's name, it falls through to here.
  app->fallthrough();
  app->add_flag_callback(
      "--quiet,-q", [] { set_quiet(true); },
      "No progress (neither the bar on a terminal nor the lines written to a log)");
  add_solve_command(*app);
  add_evaluate_command(*app);
  add_table_command(*app);
  add_study_command(*app);
  add_train_command(*app);
  add_reduce_knapsack_command(*app);
  add_fit_command(*app);
  add_score_command(*app);
  add_adapt_command(*app);
  add_fit_strength_command(*app);
  add_fit_chain_command(*app);
  add_sample_log_command(*app);
  add_plot_command(*app);
#if ONTIME_WITH_DOMAINS
  print_library_messages_once();
  add_collect_command(*app);
  add_map_command(*app);
  add_run_command(*app);
  add_tamp_command(*app);
  add_generate_world_command(*app);
  add_predict_command(*app);
#else
  for (const char* name : {"collect", "map", "run", "tamp", "generate-world", "predict"})
    add_unavailable_domain_command(*app, name);
#endif
  add_allocators_command(*app);
  // In an MPI job of several ranks, only the commands that split their work run (cluster_job.hpp).
  if (split_over_ranks(job_ranks())) {
    for (CLI::App* command : app->get_subcommands({})) {
      const std::string name = command->get_name();
      if (name == "collect" || name == "evaluate" || name == "table" || name == "study" || name == "run" ||
          name == "solve" || name == "tamp") {
        continue;
      }
      command->preparse_callback([name](std::size_t) {
        throw UsageError(
            "'" + name +
            "' does not split its work over MPI ranks (collect, evaluate, table, study, run, tamp and solve "
            "do): run it as one process");
      });
    }
  }
  return app;
}

}  // namespace ontime::cli
