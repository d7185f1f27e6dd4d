// `ontime train INSTANCE --solver ppo --out POLICY`: learns a policy by PPO from simulated
// episodes, writes it with its learning curve (CSV and PNG) as one set (OutputSet: all or
// nothing), and reports the exact success probability of the trained policy.

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <optional>

#include "common.hpp"
#include "number_options.hpp"
#include "ontime/learn/ppo_training.hpp"
#include "ontime/model/instance_io.hpp"
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
  command->add_flag("--no-plot", options->no_plot, "Write the learning curve CSV only");
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    const Problem problem = load_problem(options->instance);
    const Mdp mdp(problem);
    const std::filesystem::path policy_path(options->out);
    std::filesystem::path curve_csv = policy_path;
    curve_csv.replace_extension(".curve.csv");
    std::filesystem::path curve_png = policy_path;
    curve_png.replace_extension(".curve.png");
    std::vector<OutputFile> outputs{{"--out", policy_path}, {"--out (learning curve)", curve_csv}};
    if (!options->no_plot) outputs.push_back({"--out (learning curve plot)", curve_png});
    check_outputs(outputs, {options->instance}, MissingFolder::create);
    ProgressBar bar("train ppo");
    const PpoTraining training =
        train_ppo(mdp, options->episodes, options->seed, PpoHyperparameters{},
                  [&bar](std::uint64_t done, std::uint64_t total) { bar.update(done, total); });

    std::string csv = "epoch,episodes,steps,success_rate,mean_episode_length,actor_steps,seconds\n";
    for (const LearningCurvePoint& point : training.curve) {
      csv += fmt::format("{},{},{},{},{},{},{:.6f}\n", point.epoch, point.episodes, point.steps, point.success_rate,
                         point.mean_episode_length, point.actor_steps, point.seconds);
    }
    // The three files are one output: all are staged, then renamed together, so that an
    // interruption leaves the previous set or this one. Without a plot, an older PNG beside the
    // policy would describe another training: it goes.
    OutputSet files(policy_path.has_parent_path() ? policy_path.parent_path() : std::filesystem::path("."));
    files.write(policy_path, ppo_policy_to_json(training.policy));
    const std::filesystem::path staged_csv = files.write(curve_csv, csv);
    if (options->no_plot) {
      files.remove_on_commit(curve_png);
    } else {
      run_python_script("plot_learning_curve.py", files.stage(curve_png), [&](const std::string& drawing) {
        return std::vector<std::string>{staged_csv.string(), drawing};
      });
    }
    files.commit();

    PpoAllocator trained(mdp, std::make_shared<const PpoPolicy>(training.policy));
    // Exact evaluation takes at most kMaxExactSkeletons skeletons; a wider instance trains all
    // the same, without the exact figure.
    std::optional<ExactEvaluation> exact;
    if (problem.skeleton_count() <= kMaxExactSkeletons) exact = evaluate_exactly(mdp, trained);
    const double seconds = training.curve.empty() ? 0.0 : training.curve.back().seconds;
    if (options->json) {
      Json out;
      out["instance"] = options->instance;
      out["policy"] = policy_path.string();
      out["learning_curve"] = curve_csv.string();
      out["episodes"] = options->episodes;
      out["seed"] = options->seed;
      out["epochs"] = training.curve.size();
      out["seconds"] = seconds;
      out["exact_success_probability"] = exact ? Json(exact->success_probability) : Json(nullptr);
      print_json(out);
      return;
    }
    fmt::print("trained ppo on {} ({}): {} episodes in {} epochs, {:.1f} s\n", options->instance, problem.name(),
               options->episodes, training.curve.size(), seconds);
    if (exact) {
      fmt::print("exact success probability of the trained policy (greedy): {:.4f}\n", exact->success_probability);
    } else {
      fmt::print("exact success probability of the trained policy: not computed ({} skeletons; at most {})\n",
                 problem.skeleton_count(), kMaxExactSkeletons);
    }
    fmt::print("wrote {}\nwrote {}\n", policy_path.string(), curve_csv.string());
    if (!options->no_plot) fmt::print("wrote {}\n", curve_png.string());
  });
}

}  // namespace ontime::cli
