#include "ontime/run/regret.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ontime/solve/concurrent_solver.hpp"
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

// The losses of one allocator's episodes in fixed point (header comment): the episode under way,
// and the closed episodes' sums and squares.
class RegretTally {
 public:
  // Adds a decision's loss to the episode under way.
  void add(double loss) {
    episode_loss_ += loss;
    in_episode_ = true;
  }
  // Closes the episode under way, if any.
  void close_episode() {
    if (!in_episode_) return;
    sum_ += sum_units(episode_loss_);
    squares_ += sum_units(episode_loss_ * episode_loss_);
    ++episodes_;
    episode_loss_ = 0.0;
    in_episode_ = false;
  }
  // The counters, the episode under way included (the runner collects after the thread's last
  // episode), with V*(s0) `optimum`.
  void collect(Statistics& statistics, double optimum) const {
    const double last = in_episode_ ? episode_loss_ : 0.0;
    statistics.add(kRegretSum, sum_ + sum_units(last));
    statistics.add(kRegretSquares, squares_ + sum_units(last * last));
    statistics.add(kRegretEpisodes, static_cast<double>(episodes_ + (in_episode_ ? 1 : 0)));
    statistics.add(kRegretOptimum, optimum, Statistics::Merge::max);
  }

 private:
  double episode_loss_ = 0.0, sum_ = 0.0, squares_ = 0.0;
  std::uint64_t episodes_ = 0;
  bool in_episode_ = false;
};

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
    tally_.close_episode();
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
    tally_.add(value(before) - q);
  }
  bool is_stationary() const noexcept override { return inner_->is_stationary(); }
  void collect_statistics(Statistics& statistics) const override {
    inner_->collect_statistics(statistics);
    tally_.collect(statistics, optimum_);
  }

 private:
  double value(const State& state) { return exact_value(exact_, state, max_states_); }

  const Mdp* mdp_;
  std::unique_ptr<Allocator> inner_;
  BranchAndBoundSearch exact_;
  std::uint64_t max_states_;
  double optimum_;
  RegretTally tally_;
};

// The same along episodes acting while planning (SPEC §10): every move, a start or a step, is a
// decision, and its loss V*(s) - Q*(s, move) comes from ConcurrentSolver's optimum, memoised per
// thread. A step's loss is added when it is observed; a start is not observed (it reveals
// nothing), so its state is kept when it is chosen and its loss added with the next step's, at
// the next episode or when the counters are collected: outside the decisions' timing but for
// that copy.
class ConcurrentRegretMeter final : public ConcurrentAllocator {
 public:
  ConcurrentRegretMeter(const ConcurrentMdp& mdp, std::unique_ptr<ConcurrentAllocator> inner, std::uint64_t max_states)
      : mdp_(&mdp),
        inner_(std::move(inner)),
        exact_(mdp, max_states == 0 ? std::numeric_limits<std::size_t>::max() : max_states),
        optimum_(exact_.solve(mdp.start())) {}

  std::string_view name() const noexcept override { return inner_->name(); }
  void begin_episode(std::uint64_t seed) override {
    add_starts();
    tally_.close_episode();
    inner_->begin_episode(seed);
  }
  ConcurrentMdp::Move choose(const ConcurrentState& state) override {
    const ConcurrentMdp::Move move = inner_->choose(state);
    if (move.is_start()) starts_.emplace_back(state, move);
    return move;
  }
  void observe(const ConcurrentState& before, int choice, const ConcurrentState& after) override {
    inner_->observe(before, choice, after);
    add_starts();
    add_loss(before, {.start = -1, .refine = choice});
  }
  bool is_stationary() const noexcept override { return inner_->is_stationary(); }
  void collect_statistics(Statistics& statistics) const override {
    inner_->collect_statistics(statistics);
    add_starts();
    tally_.collect(statistics, optimum_);
  }

 private:
  void add_loss(const ConcurrentState& state, const ConcurrentMdp::Move& move) const {
    const auto value = [this](const ConcurrentState& next) { return exact_.solve(next); };
    tally_.add(value(state) - move_value(*mdp_, state, move, value));
  }
  void add_starts() const {
    for (const auto& [state, move] : starts_) add_loss(state, move);
    starts_.clear();
  }

  const ConcurrentMdp* mdp_;
  std::unique_ptr<ConcurrentAllocator> inner_;
  // (Mutable: collect_statistics adds the starts of the episode under way.)
  mutable ConcurrentSolver exact_;
  double optimum_;
  mutable RegretTally tally_;
  mutable std::vector<std::pair<ConcurrentState, ConcurrentMdp::Move>> starts_;
};

}  // namespace

AllocatorFactory with_regret(const Mdp& mdp, AllocatorFactory allocators, std::uint64_t max_states) {
  return [model = &mdp, allocators = std::move(allocators), max_states] {
    return std::make_unique<RegretMeter>(*model, allocators(), max_states);
  };
}

ConcurrentAllocatorFactory with_regret(const ConcurrentMdp& mdp, ConcurrentAllocatorFactory allocators,
                                       std::uint64_t max_states) {
  return [model = &mdp, allocators = std::move(allocators), max_states] {
    return std::make_unique<ConcurrentRegretMeter>(*model, allocators(), max_states);
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
