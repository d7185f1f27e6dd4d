// `ontime adapt INSTANCE --belief PRIOR`: repeated episodes in one world, the allocator planning
// with the prior updated online by every attempt of the episodes before (learn/online_adaptation);
// `ontime fit-strength LOG... --model MODEL`: the prior's strength that foresees the next attempts
// of worlds the model has not seen best.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "common.hpp"
#include "number_options.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/learn/online_adaptation.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/util/error.hpp"

namespace ontime::cli {

void add_adapt_command(CLI::App& app) {
  struct Options {
    std::string instance;
    std::string prior;
    std::string solver;
    AdaptationOptions adaptation;
    AllocatorFlags allocator;
    bool no_exact = false;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "adapt", "Repeated episodes in one world, planning with a prior updated by every attempt made there");
  command->add_option("INSTANCE", options->instance, "The world's true instance (JSON, SPEC §5)")->required();
  command
      ->add_option("--belief", options->prior,
                   "The prior: an instance whose distributions for INSTANCE's actions (matched by id) the "
                   "robot starts from (a prediction)")
      ->required();
  add_solver_option(*command, options->solver);
  add_number_option(*command, "--strength", options->adaptation.strength,
                    "The prior's worth in attempts (ontime fit-strength fits it)", 1e-9, 1e9);
  add_number_option(*command, "--episodes", options->adaptation.episodes, "Episodes in the world, one after another",
                    std::uint64_t{1}, std::uint64_t{100'000});
  add_number_option(*command, "--sequences", options->adaptation.sequences, "Independent sequences of episodes",
                    std::uint64_t{1}, std::uint64_t{10'000'000});
  add_number_option(*command, "--seed", options->adaptation.seed, "Seed (sequence r, episode e: stream e of stream r)");
  add_number_option(*command, "--threads", options->adaptation.threads,
                    "Worker threads (0: one per hardware thread); results do not depend on it", 0u, 1024u);
  command->add_flag("--no-exact", options->no_exact,
                    "Leave out the exact success probability of each episode's plan (any allocator)");
  command->add_flag("--json", options->json, "Print JSON");
  options->allocator.add_to(*command);
  command->callback([options] {
    check_solver_names({options->solver});
    const Problem truth = load_problem(options->instance);
    const Problem prior = load_problem(options->prior);
    AdaptationOptions adaptation = options->adaptation;
    adaptation.solver = options->solver;
    adaptation.parameters = options->allocator.values();
    adaptation.exact = !options->no_exact;
    adaptation.max_states = max_states_of(adaptation.parameters);
    try {
      (void)with_distributions_of(truth, prior);  // before any episode: the prior must fit the world
    } catch (const UsageError& error) {
      throw UsageError(options->prior + ": " + error.what() + " (--belief against " + options->instance + ")");
    }
    const AdaptationResult result = run_adaptation(truth, prior, adaptation);
    const auto sequences = static_cast<double>(result.sequences);
    if (options->json) {
      Json out;
      out["instance"] = options->instance;
      out["belief"] = options->prior;
      out["solver"] = options->solver;
      out["strength"] = adaptation.strength;
      out["episodes"] = adaptation.episodes;
      out["sequences"] = adaptation.sequences;
      out["seed"] = adaptation.seed;
      out["successes"] = result.successes;
      std::vector<double> rates;
      for (const std::uint64_t s : result.successes) rates.push_back(static_cast<double>(s) / sequences);
      out["success_rate"] = rates;
      if (adaptation.exact) out["exact_success_probability"] = result.exact;
      print_json(out);
      return;
    }
    fmt::print("{} planned from {} with {}, the prior worth {:g} attempts: {} sequences of {} episodes (seed {})\n\n",
               options->instance, options->prior, options->solver, adaptation.strength, adaptation.sequences,
               adaptation.episodes, adaptation.seed);
    fmt::print("| episode | success rate | exact success of its plan |\n|---|---|---|\n");
    for (std::size_t e = 0; e < result.successes.size(); ++e) {
      const double rate = static_cast<double>(result.successes[e]) / sequences;
      fmt::print("| {} | {:.4f} ± {:.4f} | {} |\n", e + 1, rate, 1.96 * std::sqrt(rate * (1 - rate) / sequences),
                 adaptation.exact ? fmt::format("{:.6f}", result.exact[e]) : std::string("-"));
    }
  });
}

void add_fit_strength_command(CLI::App& app) {
  struct Options {
    std::vector<std::string> logs;
    std::string model;
    std::vector<double> strengths = {0.5, 1, 2, 5, 10, 20, 50, 100, 200};
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "fit-strength", "The prior strength whose online updates foresee the next attempts of unseen worlds best");
  command->add_option("LOG", options->logs, "Planner logs of worlds the model was not fitted on, with features")
      ->required();
  command->add_option("--model", options->model, "Conditional time model (ontime fit --conditional)")->required();
  // Each strength through the command line's number parser (CLI11's own reads 0x10 as 16 and
  // drops the empty item of `1,,2`).
  command
      ->add_option_function<std::string>(
          "--strengths",
          [options](const std::string& text) {
            options->strengths.clear();
            std::size_t begin = 0;
            while (true) {
              const std::size_t comma = std::min(text.find(',', begin), text.size());
              options->strengths.push_back(cli::parse_real_option("--strengths",
                                                                  std::string_view(text).substr(begin, comma - begin),
                                                                  cli::kPositive, std::numeric_limits<double>::max()));
              if (comma == text.size()) break;
              begin = comma + 1;
            }
          },
          "Strengths to score (attempts), comma-separated")
      ->type_name("REAL,...")
      ->default_str("0.5,1,2,5,10,20,50,100,200");
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    const std::unique_ptr<ConditionalTimeModel> model = load_conditional_model(options->model);
    std::vector<std::filesystem::path> logs(options->logs.begin(), options->logs.end());
    const ConditionalData data = load_conditional_data_for(*model, options->model, logs);
    const std::vector<StrengthScore> scores = score_prior_strengths(*model, data, options->strengths);
    const auto best = std::min_element(scores.begin(), scores.end(),
                                       [](const StrengthScore& a, const StrengthScore& b) { return a.nll < b.nll; });
    if (options->json) {
      Json out;
      out["model"] = options->model;
      out["logs"] = options->logs;
      out["attempts"] = data.rows();
      Json list = Json::array();
      for (const StrengthScore& score : scores) list.push_back({{"strength", score.strength}, {"nll", score.nll}});
      out["scores"] = list;
      out["best"] = best->strength;
      print_json(out);
      return;
    }
    fmt::print("{} attempts; mean -log predictive probability of each attempt before it is seen:\n\n", data.rows());
    fmt::print("| strength | NLL |\n|---|---|\n");
    for (const StrengthScore& score : scores) fmt::print("| {:g} | {:.5f} |\n", score.strength, score.nll);
    fmt::print("\nbest strength: {:g}\n", best->strength);
  });
}

}  // namespace ontime::cli
