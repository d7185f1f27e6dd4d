// `ontime reduce-knapsack KNAPSACK.json`: writes the effort-allocation instance of the paper's
// Theorem 1 (NP-hardness by reduction from knapsack).

#include <fmt/format.h>

#include "common.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/solve/knapsack.hpp"
#include "output_paths.hpp"

namespace ontime::cli {

void add_reduce_knapsack_command(CLI::App& app) {
  struct Options {
    std::string knapsack;
    std::string out;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command =
      app.add_subcommand("reduce-knapsack", "Write the effort-allocation instance of Theorem 1 for a knapsack problem");
  command
      ->add_option("KNAPSACK", options->knapsack,
                   "Knapsack file: {\"capacity\": W, \"items\": [{\"weight\": w, \"value\": v}, ...]}")
      ->required();
  command->add_option("--out", options->out, "Instance file to write (default: standard output)");
  command->callback([options] {
    const Knapsack knapsack = load_knapsack(options->knapsack);
    const Problem problem = reduce_knapsack(knapsack, std::filesystem::path(options->knapsack).stem().string());
    if (options->out.empty()) {
      fmt::print("{}", problem_to_json(problem));
      return;
    }
    check_outputs({{"--out", options->out}}, {options->knapsack});
    save_problem(problem, options->out);
    fmt::print("wrote {}: {} single-action skeletons, deadline {}, eps = 1/(H^2 K^3) = {:.6g}\n", options->out,
               problem.skeleton_count(), problem.deadline(), reduction_epsilon(knapsack));
  });
}

}  // namespace ontime::cli
