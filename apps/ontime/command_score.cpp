// `ontime score INSTANCE LOG...`: how well an instance's distributions (a prediction, a pooled
// fit, a world's own fit) explain the attempts of planner logs: censoring-aware log score,
// integrated Brier score, execution log score (learn/attempt_scores.hpp).

#include <fmt/format.h>

#include <vector>

#include "common.hpp"
#include "number_options.hpp"
#include "ontime/learn/attempt_scores.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/report/conditional_report.hpp"

namespace ontime::cli {

void add_score_command(CLI::App& app) {
  struct Options {
    std::string instance;
    std::vector<std::string> logs;
    AttemptScoreOptions score;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "score", "Score an instance's distributions on the attempts of planner logs (log score, Brier score)");
  command->add_option("INSTANCE", options->instance, "Instance file (JSON, SPEC §5)")->required();
  command->add_option("LOG", options->logs, "Planner logs (JSON Lines)")->required();
  add_number_option(*command, "--horizon", options->score.horizon,
                    "Steps scored: later outcomes count as 'not found by then' (0: the deadline)", Steps{0},
                    Problem::kMaxDeadline);
  command
      ->add_option("--floor", options->score.floor,
                   "Least probability an outcome is scored with (impossible outcomes are counted)")
      ->capture_default_str();
  command->add_flag("--skip-unknown", options->score.skip_unknown,
                    "Skip attempts of actions the instance lacks instead of refusing them");
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    const Problem problem = load_problem(options->instance);
    std::vector<RefinementAttempt> attempts;
    for (const std::string& log : options->logs) {
      std::vector<RefinementAttempt> records = load_planner_log(log);
      attempts.insert(attempts.end(), std::make_move_iterator(records.begin()), std::make_move_iterator(records.end()));
    }
    const std::string source = options->logs.size() == 1 ? options->logs.front() : "the logs";
    const report::ScoreReport report{.instance = options->instance,
                                     .logs = options->logs,
                                     .problem = &problem,
                                     .options = options->score,
                                     .scores = score_attempts(attempts, problem, source, options->score)};
    fmt::print("{}", options->json ? report::attempt_scores_json(report) + "\n" : report::attempt_scores_text(report));
  });
}

}  // namespace ontime::cli
