#include "ontime/episode_runner.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <vector>

#include "ontime/parallel.hpp"
#include "ontime/random.hpp"
#include "ontime/session.hpp"

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

// What one thread of run_episodes keeps until the threads' results are merged.
struct ThreadRun {
  std::unique_ptr<Allocator> allocator;
  std::unique_ptr<World> world;
  RecordingTimer timer;
  std::uint64_t successes = 0;
};

}  // namespace

double ci95_half_width(double rate, std::uint64_t episodes) noexcept {
  if (episodes == 0) return 0.0;
  return 1.96 * std::sqrt(rate * (1.0 - rate) / static_cast<double>(episodes));
}

EpisodeResult run_episode(const Mdp& mdp, Allocator& allocator, World& world, std::uint64_t seed,
                          const DecisionBudget& budget, DecisionTimer* timer) {
  world.begin_episode(seed);
  Session session(mdp, allocator, stream_seed(seed, 1));
  EpisodeResult result;
  while (session.status() == Status::running) {
    Decision decision;
    if (timer != nullptr) {
      const auto start = std::chrono::steady_clock::now();
      decision = session.choose(budget);
      const auto stop = std::chrono::steady_clock::now();
      timer->record(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count());
    } else {
      decision = session.choose(budget);
    }
    ++result.decisions;
    if (decision.action < 0) {
      session.report_not_yet();
    } else {
      const Steps spent = session.state().spent[static_cast<std::size_t>(decision.skeleton)];
      session.report(world.step(decision.action, spent));
    }
  }
  result.status = session.status();
  result.solution = session.solution();
  result.steps_used = session.steps_used();
  return result;
}

MonteCarloResult run_episodes(const Mdp& mdp, const WorldFactory& worlds, const AllocatorFactory& allocators,
                              const MonteCarloOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  // Episodes are handed out in blocks: the hand-out and the progress report cost little even
  // when an episode takes a fraction of a microsecond.
  constexpr std::uint64_t kBlock = 256;
  std::vector<ThreadRun> runs(worker_count(options.episodes, options.threads));
  std::atomic<std::uint64_t> done{0};
  std::mutex progress_mutex;
  for_each_block(options.episodes, options.threads, kBlock, [&](unsigned thread) {
    ThreadRun& run = runs[thread];
    run.allocator = allocators();
    run.world = worlds();
    return [&](std::uint64_t begin, std::uint64_t end) {
      for (std::uint64_t episode = begin; episode < end; ++episode) {
        const EpisodeResult result =
            run_episode(mdp, *run.allocator, *run.world, stream_seed(options.seed, episode), options.decision_budget,
                        options.time_decisions ? &run.timer : nullptr);
        if (result.status == Status::success) ++run.successes;
        if (options.time_decisions) run.timer.end_episode();
      }
      const std::uint64_t finished = done.fetch_add(end - begin) + (end - begin);
      if (options.progress) {
        const std::lock_guard lock(progress_mutex);
        options.progress(finished, options.episodes);
      }
    };
  });

  MonteCarloResult result;
  result.episodes = options.episodes;
  std::vector<std::int64_t> samples;
  std::vector<std::int64_t> episode_totals;
  for (ThreadRun& run : runs) {
    result.successes += run.successes;
    samples.insert(samples.end(), run.timer.samples.begin(), run.timer.samples.end());
    episode_totals.insert(episode_totals.end(), run.timer.episode_totals.begin(), run.timer.episode_totals.end());
    run.allocator->collect_statistics(result.statistics);
    run.world->collect_statistics(result.world_statistics);
  }
  result.success_rate =
      options.episodes == 0 ? 0.0 : static_cast<double>(result.successes) / static_cast<double>(options.episodes);
  result.ci95 = ci95_half_width(result.success_rate, options.episodes);
  result.decision_time = summarise(samples);
  result.episode_decision_time = summarise(episode_totals);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace ontime
