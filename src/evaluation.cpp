#include "ontime/evaluation.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "expectimax.hpp"
#include "ontime/error.hpp"
#include "ontime/random.hpp"
#include "ontime/simulator.hpp"

namespace ontime {
namespace {

class RecordingTimer final : public DecisionTimer {
 public:
  void record(std::int64_t nanoseconds) override {
    samples.push_back(nanoseconds);
    episode_total += nanoseconds;
  }
  void end_episode() {
    episode_totals.push_back(episode_total);
    episode_total = 0;
  }
  std::vector<std::int64_t> samples;
  std::vector<std::int64_t> episode_totals;
  std::int64_t episode_total = 0;
};

LatencySummary summarise(std::vector<std::int64_t>& samples) {
  LatencySummary summary;
  summary.decisions = samples.size();
  if (samples.empty()) return summary;
  std::sort(samples.begin(), samples.end());
  const auto at = [&](double quantile) {
    const auto index = static_cast<std::size_t>(quantile * static_cast<double>(samples.size() - 1) + 0.5);
    return static_cast<double>(samples[index]) / 1000.0;
  };
  double total = 0;
  for (const std::int64_t sample : samples) total += static_cast<double>(sample);
  summary.mean_us = total / static_cast<double>(samples.size()) / 1000.0;
  summary.median_us = at(0.5);
  summary.p99_us = at(0.99);
  summary.max_us = static_cast<double>(samples.back()) / 1000.0;
  return summary;
}

// The allocator's own choice is the only choice; states are their own keys (packed into
// Words 64-bit words when Words > 0).
template <std::size_t Words>
class StationaryPolicy {
 public:
  StationaryPolicy(Allocator& allocator, int skeleton_count) : allocator_(&allocator), skeleton_count_(skeleton_count) {}
  void choices(const State& state, std::vector<int>& out) const {
    const int choice = allocator_->choose(state);
    if (choice < 0 || choice >= skeleton_count_) {
      throw UsageError("allocator '" + std::string(allocator_->name()) + "' chose skeleton " + std::to_string(choice) +
                       ", outside [0, " + std::to_string(skeleton_count_) + ")");
    }
    out.push_back(choice);
  }
  auto key(const State& state) const {
    if constexpr (Words > 0) {
      return detail::pack<Words>(state, skeleton_count_);
    } else {
      return state;
    }
  }

 private:
  Allocator* allocator_;
  int skeleton_count_;
};

}  // namespace

double ci95_half_width(double rate, std::uint64_t episodes) noexcept {
  if (episodes == 0) return 0.0;
  return 1.96 * std::sqrt(rate * (1.0 - rate) / static_cast<double>(episodes));
}

MonteCarloResult run_monte_carlo(const Mdp& mdp, const AllocatorFactory& factory, const MonteCarloOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  unsigned threads = options.threads == 0 ? std::max(1U, std::thread::hardware_concurrency()) : options.threads;
  threads = static_cast<unsigned>(std::min<std::uint64_t>(threads, std::max<std::uint64_t>(1, options.episodes)));

  constexpr std::uint64_t kChunk = 256;
  std::atomic<std::uint64_t> next{0};
  std::atomic<std::uint64_t> successes{0};
  std::atomic<std::uint64_t> done{0};
  std::mutex merge;
  std::mutex progress;
  std::vector<std::int64_t> samples;
  std::vector<std::int64_t> episode_totals;
  Statistics statistics;
  std::exception_ptr failure;

  const auto work = [&] {
    try {
      const std::unique_ptr<Allocator> allocator = factory();
      RecordingTimer timer;
      std::uint64_t local_successes = 0;
      for (;;) {
        const std::uint64_t begin = next.fetch_add(kChunk);
        if (begin >= options.episodes) break;
        const std::uint64_t end = std::min(options.episodes, begin + kChunk);
        for (std::uint64_t episode = begin; episode < end; ++episode) {
          const EpisodeResult result = run_episode(mdp, *allocator, stream_seed(options.seed, episode),
                                                   options.time_decisions ? &timer : nullptr, options.decision_budget);
          if (result.status == Status::success) ++local_successes;
          if (options.time_decisions) timer.end_episode();
        }
        const std::uint64_t finished = done.fetch_add(end - begin) + (end - begin);
        if (options.progress) {
          const std::lock_guard lock(progress);
          options.progress(finished, options.episodes);
        }
      }
      successes.fetch_add(local_successes);
      const std::lock_guard lock(merge);
      samples.insert(samples.end(), timer.samples.begin(), timer.samples.end());
      episode_totals.insert(episode_totals.end(), timer.episode_totals.begin(), timer.episode_totals.end());
      Statistics own;
      allocator->collect_statistics(own);
      statistics.merge(own);
    } catch (...) {
      const std::lock_guard lock(merge);
      if (!failure) failure = std::current_exception();
      next.store(options.episodes);
    }
  };

  if (threads == 1) {
    work();
  } else {
    std::vector<std::jthread> pool;
    pool.reserve(threads);
    for (unsigned i = 0; i < threads; ++i) pool.emplace_back(work);
  }
  if (failure) std::rethrow_exception(failure);

  MonteCarloResult result;
  result.episodes = options.episodes;
  result.successes = successes.load();
  result.success_rate = options.episodes == 0 ? 0.0 : static_cast<double>(result.successes) / static_cast<double>(options.episodes);
  result.ci95 = ci95_half_width(result.success_rate, options.episodes);
  result.decision_time = summarise(samples);
  result.episode_decision_time = summarise(episode_totals);
  result.statistics = std::move(statistics);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

ExactEvaluation evaluate_exactly(const Mdp& mdp, Allocator& allocator, std::size_t max_states) {
  if (!allocator.is_stationary()) {
    throw UsageError("exact evaluation needs an allocator whose choice depends only on the state; '" +
                     std::string(allocator.name()) + "' does not (use Monte Carlo)");
  }
  allocator.begin_episode(0);
  const auto run = [&](auto policy) {
    detail::Expectimax<decltype(policy)> search(mdp, policy, max_states, 0.0,
                                                "exact evaluation of " + std::string(allocator.name()));
    ExactEvaluation result;
    result.success_probability = search.solve(mdp.start()).value;
    result.states = search.memo().size();
    return result;
  };
  switch (detail::packed_words(mdp)) {
    case 2: return run(StationaryPolicy<2>(allocator, mdp.skeleton_count()));
    case 4: return run(StationaryPolicy<4>(allocator, mdp.skeleton_count()));
    default: return run(StationaryPolicy<0>(allocator, mdp.skeleton_count()));
  }
}

}  // namespace ontime
