#pragma once
// Repeated episodes in one world with the online update of online_update.hpp (docs/learning.md,
// "Online update"): a robot that starts from a prediction (the prior) and, after every episode,
// updates each action's planning-time distribution (and, for an action that backtracks, its
// backtrack distribution with it: OnlineBelief) with the attempts it made there (found after t
// steps, backtracked after t, or still unrefined after c when the episode or a backtrack ended
// it), so that the next episode's allocator plans with the posterior mean. Execution times stay
// the prior's.
//
// run_adaptation computes, for each episode index e = 0..E-1 over R independent sequences of E
// episodes in the true instance: the successes, and (when asked) the mean over the sequences of the
// exact success probability, in the truth, of the allocator planning with the posterior that
// episode e starts with (e = 0: the prior). Guarantees: the same seed gives the same numbers for
// any thread count (sequence r, episode e runs from stream_seed(stream_seed(seed, r), e)); with
// the truth as the prior and any strength it reproduces the allocator's own value at e = 0.
// Cost: R * E episodes and, with `exact`, R * E exact evaluations (each linear in the states the
// allocator reaches); one allocator factory per episode (dp-rerun: its Eq. (1) tables).
//
// score_prior_strengths scores strengths of the prior on logs of worlds a model has not seen (a
// validation set): for each world and action, the attempts in log order, each scored by the
// posterior predictive probability before it is observed (a prequential log score: how well the
// updated prediction would have foreseen the next attempt), summed over every attempt. The best
// strength is the one whose updates foresee the next attempts best. Cost: O(attempts * H) per
// strength.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/learn/conditional_model.hpp"
#include "ontime/model/problem.hpp"

namespace ontime {

struct AdaptationOptions {
  std::string solver = "dp-rerun";
  ParameterValues parameters;
  double strength = 10;           // the prior's worth in attempts (PlanningPosterior)
  std::uint64_t episodes = 10;    // E, one after another in the same world
  std::uint64_t sequences = 100;  // R, independent
  std::uint64_t seed = 1;
  unsigned threads = 0;                 // 0: one per hardware thread; the numbers do not depend on it
  bool exact = true;                    // the exact success probability of each episode's plan (stationary allocators)
  std::size_t max_states = 10'000'000;  // cap of each exact evaluation
};

struct AdaptationResult {
  std::vector<std::uint64_t> successes;  // per episode index, out of `sequences`
  std::vector<double> exact;             // per episode index (empty without `exact`)
  std::uint64_t sequences = 0;
};

// Throws UsageError for bad options, a prior lacking an action of the truth (or another deadline
// or step), an allocator that is not stationary with `exact`; ResourceLimitError past max_states.
AdaptationResult run_adaptation(const Problem& truth, const Problem& prior, const AdaptationOptions& options);

struct StrengthScore {
  double strength = 0;
  double nll = 0;  // mean -log predictive probability per attempt, nats
};

// The scores of `strengths` (each positive and finite) on `data` (rows grouped by world and
// action in their order), the prior of each group predicted by `model` from its first row's
// features; outcomes beyond the model's horizon count as cut off there, and a probability below
// 1e-9 is scored as 1e-9. Throws UsageError for no strength, a bad one, no rows, or features the
// model refuses.
std::vector<StrengthScore> score_prior_strengths(const ConditionalTimeModel& model, const ConditionalData& data,
                                                 std::span<const double> strengths);

}  // namespace ontime
