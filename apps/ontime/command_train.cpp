// `ontime train INSTANCE --solver ppo --out POLICY [--act concurrent]`: learns a policy by PPO from
// simulated episodes (plan-first or acting while planning), writes it with its learning curve (CSV
// and PNG) as one set (OutputSet: all or nothing), and reports the exact success probability of the
// trained policy.

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <optional>

#include "common.hpp"
#include "number_options.hpp"
#include "ontime/learn/ppo_training.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/report/report.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/output_set.hpp"
#include "output_paths.hpp"
#include "python_runner.hpp"

namespace ontime::cli {

void add_train_command(CLI::App& app) {
  struct Options {
    std::string instance;
    std::string solver = "ppo";
    std::uint64_t episodes = 10'000;
    std::uint64_t seed = 1;
    std::string out;
    std::string act;
    bool no_plot = false;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("train", "Learn a model-free policy (ppo) from simulated episodes");
  command->add_option("INSTANCE", options->instance, "Instance file (JSON, SPEC §5)")->required();
  command->add_option("--solver", options->solver, "Learner (only ppo)")
      ->check(CLI::IsMember({"ppo"}))
      ->capture_default_str();
  add_number_option(*command, "--episodes", options->episodes, "Training episodes", std::uint64_t{1});
  add_number_option(*command, "--seed", options->seed, "Seed of initialisation, sampling and hidden worlds");
  command->add_option("--out", options->out, "Policy file to write (JSON); the learning curve goes beside it")
      ->required();
  add_act_option(*command, options->act,
                 "Concurrent trains a policy that chooses each start and step (the ppo allocator acting while "
                 "planning)");
  command->add_flag("--no-plot", options->no_plot, "Write the learning curve CSV only");
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    Problem problem = load_problem(options->instance);
    if (!options->act.empty()) problem = problem.with_acting(*parse_acting(options->act));
    const bool concurrent = problem.acting() == Acting::concurrent;
    // The model of the mode (the plan-first Mdp refuses a problem acting while planning).
    std::optional<ConcurrentMdp> concurrent_mdp;
    std::optional<Mdp> plan_first_mdp;
    if (concurrent) {
      concurrent_mdp.emplace(problem);
    } else {
      plan_first_mdp.emplace(problem);
    }
    const std::filesystem::path policy_path(options->out);
    const std::filesystem::path curve_csv = learning_curve_path(policy_path);
    const std::filesystem::path curve_png = learning_curve_path(policy_path, ".curve.png");
    std::vector<OutputFile> outputs{{"--out", policy_path}, {"--out (learning curve)", curve_csv}};
    if (!options->no_plot) outputs.push_back({"--out (learning curve plot)", curve_png});
    check_outputs(outputs, {options->instance}, MissingFolder::create);
    ProgressBar bar("train ppo");
    const auto progress = [&bar](std::uint64_t done, std::uint64_t total) { bar.update(done, total); };
    const PpoTraining training =
        concurrent ? train_ppo(*concurrent_mdp, options->episodes, options->seed, PpoHyperparameters{}, progress)
                   : train_ppo(*plan_first_mdp, options->episodes, options->seed, PpoHyperparameters{}, progress);

    // The files are one output: all are staged, then renamed together, so that an interruption
    // leaves the previous set or this one. Without a plot, an older PNG beside the policy would
    // describe another training: it goes.
    OutputSet files(policy_path.has_parent_path() ? policy_path.parent_path() : std::filesystem::path("."));
    const std::filesystem::path staged_csv = stage_ppo_training(files, training, policy_path);
    if (options->no_plot) {
      files.remove_on_commit(curve_png);
    } else {
      run_python_script("plot_learning_curve.py", files.stage(curve_png), [&](const std::string& drawing) {
        return std::vector<std::string>{staged_csv.string(), drawing};
      });
    }
    files.commit();

    report::Training trained{.instance = options->instance,
                             .problem = &problem,
                             .policy = policy_path.string(),
                             .files = {policy_path.string(), curve_csv.string()},
                             .episodes = options->episodes,
                             .seed = options->seed,
                             .epochs = training.curve.size(),
                             .seconds = training.curve.empty() ? 0.0 : training.curve.back().seconds};
    if (!options->no_plot) trained.files.push_back(curve_png.string());
    // Exact evaluation takes at most kMaxExactSkeletons skeletons; a wider instance trains all
    // the same, without the exact figure.
    if (problem.skeleton_count() <= kMaxExactSkeletons) {
      const auto policy = std::make_shared<const PpoPolicy>(training.policy);
      ExactEvaluation exact;
      if (concurrent) {
        ConcurrentPpoAllocator greedy(*concurrent_mdp, policy);
        exact = evaluate_exactly(*concurrent_mdp, greedy);
      } else {
        PpoAllocator greedy(*plan_first_mdp, policy);
        exact = evaluate_exactly(*plan_first_mdp, greedy);
      }
      trained.exact = exact.success_probability;
      // As evaluate reports it: the expected reward beside the success for an instance with rewards.
      if (problem.has_rewards()) trained.exact_reward = exact.expected_reward;
    }
    fmt::print("{}", options->json ? report::to_json(trained) + "\n" : report::to_text(trained));
  });
}

}  // namespace ontime::cli
