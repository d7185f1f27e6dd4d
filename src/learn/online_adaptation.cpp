#include "ontime/learn/online_adaptation.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <utility>

#include "ontime/learn/online_belief.hpp"
#include "ontime/learn/online_update.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/parallel.hpp"
#include "ontime/util/random.hpp"

namespace ontime {

AdaptationResult run_adaptation(const Problem& truth, const Problem& prior, const AdaptationOptions& options) {
  if (!(std::isfinite(options.strength) && options.strength > 0)) {
    throw UsageError("the prior's strength must be a positive number of attempts");
  }
  if (options.episodes < 1 || options.sequences < 1) throw UsageError("episodes and sequences must be at least 1");
  const Problem prior_on_truth = with_distributions_of(truth, prior);
  const Mdp truth_mdp(truth);

  AdaptationResult result;
  result.sequences = options.sequences;
  const std::uint64_t episodes = options.episodes;
  std::vector<std::uint8_t> succeeded(options.sequences * episodes, 0);
  std::vector<double> exact(options.exact ? options.sequences * episodes : 0, 0.0);
  for_each_block(options.sequences, options.threads, 1, [&](unsigned) {
    return [&](std::uint64_t begin, std::uint64_t end) {
      for (std::uint64_t r = begin; r < end; ++r) {
        OnlineBelief belief(prior_on_truth, options.strength);
        HiddenWorld world(truth, 0);
        const std::uint64_t sequence_seed = stream_seed(options.seed, r);
        for (std::uint64_t e = 0; e < episodes; ++e) {
          const Problem believed = belief.believed();
          const Mdp belief_mdp(believed);
          const AllocatorFactory factory = make_allocator_factory(options.solver, belief_mdp, options.parameters);
          if (options.exact) {
            const std::unique_ptr<Allocator> judged = factory();
            exact[r * episodes + e] = evaluate_exactly(truth_mdp, *judged, options.max_states).success_probability;
          }
          // The allocator plans with the belief; the truth's transitions answer (the same state
          // layout: the belief is the truth's structure).
          const std::unique_ptr<Allocator> allocator = factory();
          const EpisodeResult episode = run_episode(truth_mdp, *allocator, world, stream_seed(sequence_seed, e));
          succeeded[r * episodes + e] = episode.status == Status::success ? 1 : 0;
          belief.observe(truth, episode.attempts);
        }
      }
    };
  });
  result.successes.assign(episodes, 0);
  if (options.exact) result.exact.assign(episodes, 0.0);
  for (std::uint64_t r = 0; r < options.sequences; ++r) {
    for (std::uint64_t e = 0; e < episodes; ++e) {
      result.successes[e] += succeeded[r * episodes + e];
      if (options.exact) result.exact[e] += exact[r * episodes + e];
    }
  }
  for (double& value : result.exact) value /= static_cast<double>(options.sequences);
  return result;
}

std::vector<StrengthScore> score_prior_strengths(const ConditionalTimeModel& model, const ConditionalData& data,
                                                 std::span<const double> strengths) {
  if (strengths.empty()) throw UsageError("give at least one strength");
  for (const double strength : strengths) {
    if (!(std::isfinite(strength) && strength > 0)) throw UsageError("every strength must be positive and finite");
  }
  if (data.rows() == 0) throw UsageError("no attempts to score the strengths on");
  // The groups in order of their first row: one action in one world.
  std::map<std::pair<std::string, std::string>, std::size_t> group_of;
  std::vector<std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < data.rows(); ++i) {
    const auto [slot, added] = group_of.try_emplace({data.worlds[i], data.actions[i]}, groups.size());
    if (added) groups.emplace_back();
    groups[slot->second].push_back(i);
  }
  const Steps horizon = model.horizon();
  std::vector<Distribution> priors;
  priors.reserve(groups.size());
  for (const std::vector<std::size_t>& rows : groups) priors.push_back(model.predict(data.row(rows.front())).planning);

  constexpr double kFloor = 1e-9;
  std::vector<StrengthScore> scores;
  scores.reserve(strengths.size());
  for (const double strength : strengths) {
    double nll = 0;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      PlanningPosterior posterior(priors[g], horizon, strength);
      for (const std::size_t i : groups[g]) {
        const bool found = data.found[i] != 0 && data.planning[i] <= horizon;
        const Steps t = std::min(data.planning[i], horizon);
        const double p = found ? posterior.predictive_found(std::max<Steps>(t, 1)) : posterior.predictive_cut_off(t);
        nll -= std::log(std::max(p, kFloor));
        if (found) {
          posterior.observe_found(std::max<Steps>(t, 1));
        } else {
          posterior.observe_cut_off(t);
        }
      }
    }
    scores.push_back({strength, nll / static_cast<double>(data.rows())});
  }
  return scores;
}

}  // namespace ontime
