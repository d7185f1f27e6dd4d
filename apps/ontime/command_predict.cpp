// `ontime predict --domain NAME --world FILE --model MODEL --output INSTANCE`: the instance of a
// world never refined before, its actions' distributions predicted by a conditional time model
// (`fit --conditional`) from the world's geometry alone (domains::predict_instance).

#include <fmt/format.h>

#include <chrono>
#include <filesystem>

#include "common.hpp"
#include "number_options.hpp"
#include "ontime/domains/predict.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/model/instance_io.hpp"
#include "output_paths.hpp"

namespace ontime::cli {

void add_predict_command(CLI::App& app) {
  struct Options {
    std::string domain;
    std::string world;
    std::string model;
    std::string output;
    domains::PredictOptions predict;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command =
      app.add_subcommand("predict", "Write the instance of an unseen world from a conditional time model");
  command->add_option("--domain", options->domain, "Domain (navigation)")->required();
  command->add_option("--world", options->world, "World file")->required();
  command->add_option("--model", options->model, "Conditional time model (ontime fit --conditional)")->required();
  command->add_option("-o,--output", options->output, "Instance file to write (SPEC §5)")->required();
  add_number_option(*command, "--deadline", options->predict.deadline, "Deadline in steps (0: the world file's)",
                    Steps{0}, Problem::kMaxDeadline);
  command->add_flag("--library", options->predict.library,
                    "Every action of the world as a skeleton of its own, even when the world lists skeletons");
  command->add_option("--name", options->predict.name, "Instance name (default: the world's name)");
  add_threads_option(*command, options->predict.threads,
                     "Threads computing the actions' features (0: one per hardware thread)");
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    check_outputs({{"--output", options->output}}, {options->world, options->model});
    const domains::LoadedDomain loaded = domains::load_domain(options->domain, options->world);
    const std::unique_ptr<ConditionalTimeModel> model = load_conditional_model(options->model);
    const auto started = std::chrono::steady_clock::now();
    const Problem problem = domains::predict_instance(*loaded.domain, loaded.defaults, *model, options->predict);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    save_problem(problem, options->output);
    if (options->json) {
      Json out;
      out["instance"] = options->output;
      out["kind"] = model->kind();
      out["actions"] = problem.action_count();
      out["skeletons"] = problem.skeleton_count();
      out["deadline"] = problem.deadline();
      out["step_seconds"] = problem.step_seconds();
      out["seconds"] = seconds;
      print_json(out);
      return;
    }
    fmt::print(
        "Predicted {} actions ({} skeletons, deadline {} steps of {} s) of {} with a {} model in {:.2f} ms: "
        "wrote {}.\n",
        problem.action_count(), problem.skeleton_count(), problem.deadline(), problem.step_seconds(), options->world,
        model->kind(), 1e3 * seconds, options->output);
  });
}

}  // namespace ontime::cli
