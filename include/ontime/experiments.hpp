#pragma once
// The computation-time studies of the paper's §VIII-C (Figs. 4-6): how much meta-level
// computation mcts needs against dp-rerun, how mcts fares when held to dp-rerun's time, and
// how its success grows with time. Each returns the measured numbers; writing and plotting
// them is the caller's business.
//
// Times are wall-clock on the running machine: the success counts of iteration budgets are
// reproducible for a seed, those of time budgets are not (the number of iterations that fit
// in a time depends on the machine and its load).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "ontime/allocators.hpp"
#include "ontime/evaluation.hpp"

namespace ontime {

struct StudySettings {
  std::uint64_t episodes = 1'000;  // per evaluated configuration
  std::uint64_t seed = 1;
  unsigned threads = 0;
  AllocatorOptions allocator;      // mcts and dp-rerun settings (budget overridden where a study sets it)
  // Called with the episodes done so far in this study and its total.
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
};

// Mean seconds one decision of the allocator takes, over the states it meets in `episodes` of
// its own episodes, timed in bulk (no clock read per decision).
double mean_decision_seconds(const Mdp& mdp, const AllocatorFactory& factory, std::uint64_t seed,
                             std::uint64_t episodes = 500);

// Fig. 4: total decision time per episode, mcts (its iteration budget) against dp-rerun.
struct ComputeTimeStudy {
  MonteCarloResult mcts;
  MonteCarloResult dp_rerun;
};
ComputeTimeStudy compute_time_study(const Mdp& mdp, const StudySettings& settings);

// Fig. 5: mcts given exactly dp-rerun's measured time per decision.
struct EqualTimeStudy {
  double dp_rerun_decision_seconds = 0;
  MonteCarloResult dp_rerun;
  MonteCarloResult mcts;
};
EqualTimeStudy equal_time_study(const Mdp& mdp, const StudySettings& settings);

// Fig. 6: mcts success against log10 of a multiplier of dp-rerun's time per decision.
struct AnytimePoint {
  double log10_multiplier = 0;
  double seconds_per_decision = 0;
  MonteCarloResult mcts;
};
struct AnytimeStudy {
  double dp_rerun_decision_seconds = 0;
  double optimum = 0;               // exact, from `optimal`
  MonteCarloResult dp_rerun;
  std::vector<AnytimePoint> points;
};
AnytimeStudy anytime_study(const Mdp& mdp, const std::vector<double>& log10_multipliers,
                           const StudySettings& settings);

}  // namespace ontime
