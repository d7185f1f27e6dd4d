#pragma once
// The computation-time studies of the paper's §VIII-C (Figs. 4-6): how much meta-level
// computation an anytime allocator (the searcher; the paper's mcts) needs against a stationary
// one (the reference; the paper's dp-rerun), how the searcher fares when held to the
// reference's time per decision, and how its success grows with time. The searcher's time is
// given through the budget passed with each decision, so one factory serves every time
// setting. Each returns the measured numbers; writing and plotting them is the caller's
// business.
//
// Times are wall-clock on the running machine: the success counts of iteration budgets are
// reproducible for a seed, those of time budgets are not (the number of iterations that fit
// in a time depends on the machine and its load).

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/util/memory.hpp"

namespace ontime {

struct StudySettings {
  std::uint64_t episodes = 1'000;  // per evaluated configuration
  std::uint64_t seed = 1;
  unsigned threads = 0;
  std::string searcher = "mcts";       // an anytime allocator kind
  std::string reference = "dp-rerun";  // a stationary allocator kind
  ParameterValues parameters;          // of both kinds (the searcher's time is set per study)
  // Called with the episodes done so far in this study and its total.
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
  // When set, every evaluation's episodes are split over these ranks (MonteCarloOptions::ranks),
  // and the reference's time per decision is rank 0's measurement, so that every rank gives the
  // searcher the same budget.
  const Ranks* ranks = nullptr;
};

// Mean seconds one decision of the allocator takes, over the states it meets in `episodes` of
// its own episodes, timed in bulk (no clock read per decision).
double mean_decision_seconds(const Mdp& mdp, const AllocatorFactory& factory, std::uint64_t seed,
                             std::uint64_t episodes = 500);
// The same acting while planning (SPEC §10): every move, a start or a step, is a decision.
double mean_decision_seconds(const ConcurrentMdp& mdp, const ConcurrentAllocatorFactory& factory, std::uint64_t seed,
                             std::uint64_t episodes = 500);

// Fig. 4: total decision time per episode, the searcher (its own default budget) against the
// reference.
struct ComputeTimeStudy {
  MonteCarloResult searcher;
  MonteCarloResult reference;
};
// Runs `settings.episodes` episodes of each allocator on `mdp`, the searcher within its default budget.
ComputeTimeStudy compute_time_study(const Mdp& mdp, const StudySettings& settings);
// The same acting while planning (SPEC §10): each allocator by its commit rule, every move a
// decision; the searcher's time per decision is its `time-budget` parameter.
ComputeTimeStudy compute_time_study(const ConcurrentMdp& mdp, const StudySettings& settings);

// Fig. 5: the searcher given exactly the reference's measured time per decision.
struct EqualTimeStudy {
  double reference_decision_seconds = 0;
  MonteCarloResult reference;
  MonteCarloResult searcher;
};
// Measures the reference's mean seconds per decision, then runs the episodes of each allocator, the searcher
// within that time per decision.
EqualTimeStudy equal_time_study(const Mdp& mdp, const StudySettings& settings);
// The same acting while planning (SPEC §10), the searcher made with that time as its `time-budget`.
EqualTimeStudy equal_time_study(const ConcurrentMdp& mdp, const StudySettings& settings);

// Fig. 6: the searcher's success against log10 of a multiplier of the reference's time per
// decision.
struct AnytimePoint {
  double log10_multiplier = 0;
  double seconds_per_decision = 0;
  MonteCarloResult searcher;
};
struct AnytimeStudy {
  double reference_decision_seconds = 0;
  double optimum = 0;  // exact (the optimal solver, within the max-states parameter)
  MonteCarloResult reference;
  std::vector<AnytimePoint> points;
};
// The reference's time per decision, its episodes and the exact optimum, then the searcher's episodes at that
// time times 10^m for each m of `log10_multipliers` (each within [-3, 9], else UsageError).
AnytimeStudy anytime_study(const Mdp& mdp, const std::vector<double>& log10_multipliers, const StudySettings& settings);
// The same acting while planning (SPEC §10); the optimum is ConcurrentSolver's.
AnytimeStudy anytime_study(const ConcurrentMdp& mdp, const std::vector<double>& log10_multipliers,
                           const StudySettings& settings);

// A study over several instances: one of the three above on each, in order.
enum class StudyKind { compute_time, equal_time, anytime };
// "compute-time", "equal-time", "anytime"; UsageError for another name.
StudyKind study_kind(std::string_view name);
std::string_view to_string(StudyKind kind) noexcept;

struct StudyInstance {
  Problem problem;
  std::string source;  // a file, for messages
  std::string label;   // the instance's column in the CSV
};

struct StudyRows {
  StudyKind kind = StudyKind::compute_time;
  std::vector<std::string> labels;  // one per instance
  std::vector<ComputeTimeStudy> compute_time;
  std::vector<EqualTimeStudy> equal_time;
  std::vector<AnytimeStudy> anytime;
  std::vector<double> log10_multipliers;  // anytime
};

// Checks what can be checked before the work: the searcher anytime and the reference stationary
// (UsageError), the memory the searcher may hold on each instance (the registry's check_memory)
// and, for the anytime study, the exact optimum's (check_exact_work); `spelling` names the
// parameters in messages.
void check_study_request(StudyKind kind, const std::vector<StudyInstance>& instances, const StudySettings& settings,
                         const ParameterSpelling& spelling = nullptr);

// Runs the study on every instance, each in its acting mode (Problem::acting(): planning first,
// or acting while planning, SPEC §10). `settings.progress` sees the episodes done over all of them.
StudyRows run_study(StudyKind kind, const std::vector<StudyInstance>& instances, const StudySettings& settings,
                    const std::vector<double>& log10_multipliers = {});

}  // namespace ontime
