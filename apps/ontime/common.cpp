#include "common.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <fmt/format.h>
#include <unistd.h>

#include "ontime/error.hpp"

namespace ontime::cli {

void AllocatorFlags::add_to(CLI::App& command) {
  command.add_option("--aggregation", aggregation, "How dp-rerun's Eq. (1) combines skeletons sharing an action")
      ->check(CLI::IsMember({"sum", "max", "self"}))
      ->capture_default_str();
  command.add_option("--max-states", max_states, "Cap on the states the exact solver and evaluator may hold")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command.add_option("--iterations", iterations,
                     "mcts: search iterations per decision (default 10000; no limit when only --time-budget is given)")
      ->check(CLI::PositiveNumber);
  command.add_option("--time-budget", time_budget,
                     "mcts: seconds per decision (with --iterations, whichever ends first; 0: no time limit)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command.add_option("--exploration", exploration, "mcts: exploration constant C of UCT")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command.add_option("--rollout", rollout, "mcts: rollout policy, 'random' or a stationary allocator (e.g. dp-rerun)")
      ->capture_default_str();
  command.add_option("--policy", policies,
                     "ppo: trained policy file (ontime train); for several instances, one per instance in order");
  command.add_option("--max-tree-mib", max_tree_mib, "mcts: memory cap of the search tree; a search stops there")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
}

AllocatorOptions AllocatorFlags::options(std::size_t index, std::size_t instance_count) const {
  AllocatorOptions options;
  if (!policies.empty()) {
    if (policies.size() != 1 && policies.size() != instance_count) {
      throw UsageError(fmt::format("--policy: give one policy file, or one per instance ({} given for {} instances)",
                                   policies.size(), instance_count));
    }
    options.policy = std::make_shared<const PpoPolicy>(load_ppo_policy(policies[policies.size() == 1 ? 0 : index]));
  }
  options.aggregation = parse_aggregation(aggregation);
  options.max_states = max_states;
  options.exploration = exploration;
  if (time_budget > 0) options.seconds = time_budget;
  if (iterations > 0) {
    options.iterations = iterations;
  } else if (time_budget > 0) {
    options.iterations = std::numeric_limits<std::uint64_t>::max();
  }
  if (rollout != "random") check_solver_names({rollout});
  options.rollout = rollout;
  options.max_tree_bytes = max_tree_mib << 20;
  return options;
}

void MonteCarloFlags::add_to(CLI::App& command) {
  command.add_option("--episodes", episodes, "Simulated episodes per evaluation")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command.add_option("--seed", seed, "Seed of the hidden worlds (episode i uses stream i of it)")->capture_default_str();
  command.add_option("--threads", threads, "Worker threads (0: one per hardware thread); results do not depend on it")
      ->capture_default_str();
}

MonteCarloOptions MonteCarloFlags::options() const {
  MonteCarloOptions options;
  options.episodes = episodes;
  options.seed = seed;
  options.threads = threads;
  return options;
}

CLI::Option* add_solver_option(CLI::App& command, std::string& solver) {
  return command.add_option("--solver", solver, "Allocator: " + fmt::format("{}", fmt::join(allocator_names(), ", ")))
      ->required();
}

void check_solver_names(const std::vector<std::string>& names) {
  const std::vector<std::string> known = allocator_names();
  for (const std::string& name : names) {
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      throw UsageError(fmt::format("unknown solver '{}' (known: {})", name, fmt::join(known, ", ")));
    }
  }
}

void print_json(const Json& value) { fmt::print("{}\n", value.dump(2)); }

ProgressBar::ProgressBar(std::string label) : label_(std::move(label)), enabled_(::isatty(STDERR_FILENO) != 0) {}

ProgressBar::~ProgressBar() {
  if (enabled_ && last_percent_ >= 0) fmt::print(stderr, "\r\033[K");
}

void ProgressBar::update(std::uint64_t done, std::uint64_t total) {
  if (!enabled_ || total == 0) return;
  const int percent = static_cast<int>(100 * done / total);
  if (percent == last_percent_) return;
  last_percent_ = percent;
  constexpr int kWidth = 30;
  const int filled = percent * kWidth / 100;
  fmt::print(stderr, "\r{} [{}{}] {:3d}%", label_, std::string(static_cast<std::size_t>(filled), '#'),
             std::string(static_cast<std::size_t>(kWidth - filled), '.'), percent);
  std::fflush(stderr);
}

}  // namespace ontime::cli
