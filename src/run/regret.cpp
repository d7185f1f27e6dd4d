#include "ontime/run/regret.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "ontime/solve/search_solver.hpp"
#include "ontime/util/error.hpp"

namespace ontime {
namespace {

double exact_value(BranchAndBoundSearch& search, const State& state, std::uint64_t max_states) {
  const SearchSolution solution = search.search(state);
  if (!solution.exact) {
    throw ResourceLimitError("regret: the exact values need more than " + std::to_string(max_states) + " states");
  }
  return solution.lower;
}

class RegretMeter final : public Allocator {
 public:
  // Solves V*(s0) first: the losses of the first decisions need its subtree anyway.
  RegretMeter(const Mdp& mdp, std::unique_ptr<Allocator> inner, std::uint64_t max_states)
      : mdp_(&mdp),
        inner_(std::move(inner)),
        exact_(mdp, max_states),
        max_states_(max_states),
        optimum_(value(mdp.start())) {}

  std::string_view name() const noexcept override { return inner_->name(); }
  void begin_episode(std::uint64_t seed) override {
    close_episode();
    inner_->begin_episode(seed);
  }
  int choose(const State& state) override { return inner_->choose(state); }
  int choose(const State& state, const DecisionBudget& budget) override { return inner_->choose(state, budget); }
  void observe(const State& before, int choice, const State& after, Status status) override {
    inner_->observe(before, choice, after, status);
    if (mdp_->useful_choices(before).empty()) return;  // an idle step: nothing to choose
    double q = 0.0;
    mdp_->for_each_outcome(before, choice, [&](double probability, Status outcome, const State& next) {
      if (outcome == Status::success) q += probability * mdp_->success_reward(next, choice);
      if (outcome == Status::running) q += probability * value(next);
    });
    episode_loss_ += value(before) - q;
    in_episode_ = true;
  }
  bool is_stationary() const noexcept override { return inner_->is_stationary(); }
  void collect_statistics(Statistics& statistics) const override {
    inner_->collect_statistics(statistics);
    // The episode under way counts too (the runner collects after the thread's last episode).
    const double last = in_episode_ ? episode_loss_ : 0.0;
    statistics.add(kRegretSum, sum_ + units(last));
    statistics.add(kRegretSquares, squares_ + units(last * last));
    statistics.add(kRegretEpisodes, static_cast<double>(episodes_ + (in_episode_ ? 1 : 0)));
    statistics.add(kRegretOptimum, optimum_, Statistics::Merge::max);
  }

 private:
  void close_episode() {
    if (!in_episode_) return;
    sum_ += units(episode_loss_);
    squares_ += units(episode_loss_ * episode_loss_);
    ++episodes_;
    episode_loss_ = 0.0;
    in_episode_ = false;
  }

  // A whole number of kRegretUnit: sums of them are exact in any order.
  static double units(double value) { return sum_units(value); }

  double value(const State& state) { return exact_value(exact_, state, max_states_); }

  const Mdp* mdp_;
  std::unique_ptr<Allocator> inner_;
  BranchAndBoundSearch exact_;
  std::uint64_t max_states_;
  double optimum_;
  double episode_loss_ = 0.0, sum_ = 0.0, squares_ = 0.0;
  std::uint64_t episodes_ = 0;
  bool in_episode_ = false;
};

}  // namespace

AllocatorFactory with_regret(const Mdp& mdp, AllocatorFactory allocators, std::uint64_t max_states) {
  return [model = &mdp, allocators = std::move(allocators), max_states] {
    return std::make_unique<RegretMeter>(*model, allocators(), max_states);
  };
}

std::optional<RegretEstimate> regret_estimate(const Statistics& statistics) {
  const auto sum = statistics.find(kRegretSum);
  const auto squares = statistics.find(kRegretSquares);
  const auto episodes = statistics.find(kRegretEpisodes);
  const auto optimum = statistics.find(kRegretOptimum);
  if (!sum || !squares || !episodes || !optimum || *episodes < 1) return std::nullopt;
  RegretEstimate estimate;
  estimate.optimum = *optimum;
  estimate.episodes = static_cast<std::uint64_t>(*episodes);
  const MeanInterval interval = mean_interval_of_units(*sum, *squares, *episodes);
  estimate.mean = interval.mean;
  estimate.ci95 = interval.ci95;
  return estimate;
}

}  // namespace ontime
