// The whole `ontime` command line: every command registered on one CLI::App.

#include "common.hpp"

namespace ontime::cli {

std::unique_ptr<CLI::App> make_app() {
  auto app = std::make_unique<CLI::App>(
      "OnTime: deadline-aware effort allocation for task and motion planning.\n"
      "Decides, step by step, which plan skeleton gets the motion planner's next slice of effort.",
      "ontime");
  app->set_version_flag("--version", std::string("ontime ") + ONTIME_VERSION);
  app->require_subcommand(1);
  add_solve_command(*app);
  add_evaluate_command(*app);
  add_table_command(*app);
  add_study_command(*app);
  add_train_command(*app);
  add_reduce_knapsack_command(*app);
  add_fit_command(*app);
  add_sample_log_command(*app);
  add_plot_command(*app);
  add_collect_command(*app);
  add_map_command(*app);
  add_run_command(*app);
  add_allocators_command(*app);
  return app;
}

}  // namespace ontime::cli
