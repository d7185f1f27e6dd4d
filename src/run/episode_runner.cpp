#include "ontime/run/episode_runner.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <vector>

#include "ontime/run/concurrent_session.hpp"
#include "ontime/run/session.hpp"
#include "ontime/util/byte_packing.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/parallel.hpp"
#include "ontime/util/random.hpp"
#include "ontime/util/ranks.hpp"

namespace ontime {
namespace {

class RecordingTimer final : public DecisionTimer {
 public:
  void record(std::int64_t nanoseconds) override {
    decisions.add(nanoseconds);
    episode_total += nanoseconds;
  }
  void end_episode() {
    episodes.add(episode_total);
    episode_total = 0;
  }
  LatencyHistogram decisions;
  LatencyHistogram episodes;  // the total decision time of each episode
  std::int64_t episode_total = 0;
};

// A live run's charges (LiveTotals, field for field) summed in whole nanoseconds, so that the
// sums do not depend on how episodes fell to threads or ranks.
struct LiveNanoseconds {
  std::int64_t decision = 0, planning = 0, overrun = 0, outside = 0, elapsed = 0;

  void add(const LiveTotals& episode) noexcept {
    decision += std::llround(episode.decision * 1e9);
    planning += std::llround(episode.planning * 1e9);
    overrun += std::llround(episode.overrun * 1e9);
    outside += std::llround(episode.outside * 1e9);
    elapsed += std::llround(episode.elapsed * 1e9);
  }
  void add(const LiveNanoseconds& other) noexcept {
    decision += other.decision;
    planning += other.planning;
    overrun += other.overrun;
    outside += other.outside;
    elapsed += other.elapsed;
  }
  // The mean of `episodes` episodes, in seconds.
  LiveTotals mean(std::uint64_t episodes) const noexcept {
    const double scale = 1e-9 / static_cast<double>(episodes);
    return {.decision = static_cast<double>(decision) * scale,
            .planning = static_cast<double>(planning) * scale,
            .overrun = static_cast<double>(overrun) * scale,
            .outside = static_cast<double>(outside) * scale,
            .elapsed = static_cast<double>(elapsed) * scale};
  }
};

// The rewards of episodes (SPEC §8) in statistics.hpp's order-free units, so that the sums do not
// depend on the order threads and ranks add them in. Kept as integers: each episode adds up to
// 2^32 units, which a double would hold exactly only up to 2^21 episodes.
struct RewardSum {
  std::uint64_t units = 0;
  std::uint64_t square_units = 0;

  void add(double reward) noexcept {
    units += static_cast<std::uint64_t>(sum_units(reward));
    square_units += static_cast<std::uint64_t>(sum_units(reward * reward));
  }
  void add(const RewardSum& other) noexcept {
    units += other.units;
    square_units += other.square_units;
  }
};

// What one thread of run_episodes keeps until the threads' results are merged.
struct ThreadRun {
  std::unique_ptr<Allocator> allocator;
  std::unique_ptr<ConcurrentAllocator> concurrent_allocator;  // acting while planning (SPEC §10)
  std::unique_ptr<World> world;
  RecordingTimer timer;
  std::uint64_t successes = 0;
  RewardSum rewards;
  LiveNanoseconds live_nanoseconds;  // live runs: this thread's episodes' charges
  std::uint64_t model_successes = 0;
  std::uint64_t model_undecided = 0;
};

}  // namespace

double ci95_half_width(double rate, std::uint64_t episodes) noexcept {
  if (episodes == 0) return 0.0;
  return 1.96 * std::sqrt(rate * (1.0 - rate) / static_cast<double>(episodes));
}

namespace {

// The task planner's turn in a streaming episode, between two decisions.
struct Arrivals {
  const StreamingRun* streaming = nullptr;
  World* world = nullptr;
  bool open = true;          // the planner may find more
  int steps_since_last = 0;  // steps decided since the last skeleton arrived
  int found = 0;             // skeletons found so far (acting while planning retires some)
};

// The next skeleton into a session that owns its problem (Session or ConcurrentSession).
template <class AnySession>
void take_next_skeleton(AnySession& session, Arrivals& arrivals) {
  std::optional<FoundSkeleton> found;
  if (session.problem().skeleton_count() < arrivals.streaming->max_skeletons) found = arrivals.world->next_skeleton();
  if (!found) {
    arrivals.open = false;
    session.expect_more_skeletons(false);
    return;
  }
  if (session.is_live()) session.charge_outside(found->charged_seconds);
  session.add_skeleton(found->action_ids, std::move(found->new_actions));
  arrivals.steps_since_last = 0;
  ++arrivals.found;
}

// The one loop of the runner's episodes: the allocator decides, the session carries the step
// out in the world (Session::carry_out, the step ppo training and the Python environment take
// too), until the session ends (and, in a streaming episode, skeletons arrive between decisions).
EpisodeResult drive(Session& session, World& world, const DecisionBudget& budget, DecisionTimer* timer,
                    const std::optional<LiveRun>& live, Arrivals* arrivals) {
  EpisodeResult result;
  while (session.status() == Status::running) {
    if (arrivals != nullptr && arrivals->open &&
        (arrivals->steps_since_last >= arrivals->streaming->period || !session.can_succeed())) {
      take_next_skeleton(session, *arrivals);
      continue;
    }
    Decision decision;
    if (timer != nullptr) {
      const auto start = std::chrono::steady_clock::now();
      decision = session.choose(budget);
      const auto stop = std::chrono::steady_clock::now();
      timer->record(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count());
    } else {
      decision = session.choose(budget);
    }
    if (decision.skeleton < 0) break;  // a live session ran out of time before deciding
    ++result.decisions;
    session.carry_out(world);
    if (arrivals != nullptr) ++arrivals->steps_since_last;
  }
  result.status = session.status();
  result.solution = session.solution();
  result.reward = session.reward();
  result.steps_used = session.steps_used();
  result.skeletons = session.problem().skeleton_count();
  result.attempts = session.take_attempts();
  if (live) {
    result.live = session.totals();
    result.model_status = session.model_status();
    if (live->keep_timeline) {
      result.timeline = session.timeline();
      result.executions = session.executions();
    }
  }
  return result;
}

// The loop of concurrent episodes (SPEC §10): the allocator's moves through the session, a start
// carried out at once, a step in the world, until the session ends.
EpisodeResult drive_concurrent(ConcurrentSession& session, World& world, DecisionTimer* timer,
                               const std::optional<LiveRun>& live, Arrivals* arrivals = nullptr) {
  EpisodeResult result;
  while (session.status() == Status::running) {
    if (arrivals != nullptr && arrivals->open &&
        (arrivals->steps_since_last >= arrivals->streaming->period || !session.can_succeed())) {
      take_next_skeleton(session, *arrivals);
      continue;
    }
    ConcurrentDecision decision;
    if (timer != nullptr) {
      const auto start = std::chrono::steady_clock::now();
      decision = session.choose();
      const auto stop = std::chrono::steady_clock::now();
      timer->record(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count());
    } else {
      decision = session.choose();
    }
    ++result.decisions;
    if (decision.is_start() && arrivals != nullptr && session.status() == Status::running) {
      // The robot committed: the skeletons not through what it executed leave, and the task
      // planner streams only skeletons through it from now on.
      session.retire_dropped();
      world.commit(session.started());
    }
    if (!decision.is_start() && session.status() == Status::running) {
      session.carry_out(world);
      if (arrivals != nullptr) ++arrivals->steps_since_last;
    }
  }
  result.status = session.status();
  result.solution = session.solution();
  result.reward = session.reward();
  result.steps_used = session.steps_used();
  result.skeletons = session.mdp().skeleton_count();
  result.attempts = session.take_attempts();
  if (live) {
    result.live = session.totals();
    if (live->keep_timeline) {
      result.timeline = session.timeline();
      result.executions = session.executions();
    }
  }
  return result;
}

const Clock& clock_of(const World& world) {
  static const SteadyClock steady_clock;
  return world.clock() != nullptr ? *world.clock() : steady_clock;
}

}  // namespace

EpisodeResult run_episode(const Mdp& mdp, Allocator& allocator, World& world, std::uint64_t seed,
                          const DecisionBudget& budget, DecisionTimer* timer, const std::optional<LiveRun>& live) {
  world.begin_episode(seed);
  Session session = live ? Session(mdp, allocator, stream_seed(seed, 1), clock_of(world), live->options)
                         : Session(mdp, allocator, stream_seed(seed, 1));
  return drive(session, world, budget, timer, live, nullptr);
}

namespace {

// A streaming episode's first skeleton, the problem it makes, and its search time on the clock.
struct FirstSkeleton {
  Problem problem;
  double charged_seconds = 0;
};

std::optional<FirstSkeleton> first_skeleton(const StreamingRun& streaming, World& world, const Clock& clock) {
  if (streaming.max_skeletons < 1 || streaming.period < 1) {
    throw UsageError("streaming episodes need at least 1 skeleton and a period of at least 1 step");
  }
  const double search_began = clock.now();
  std::optional<FoundSkeleton> first = world.next_skeleton();
  const double first_search = clock.now() - search_began;
  if (!first) return std::nullopt;
  std::vector<int> path;
  for (const std::string& id : first->action_ids) {
    int index = -1;
    for (std::size_t a = 0; a < first->new_actions.size() && index < 0; ++a) {
      if (first->new_actions[a].id == id) index = static_cast<int>(a);
    }
    if (index < 0) throw UsageError("the first skeleton found names action '" + id + "' without bringing it");
    path.push_back(index);
  }
  return FirstSkeleton{Problem(streaming.name, streaming.deadline, streaming.step_seconds,
                               std::move(first->new_actions), {std::move(path)}),
                       first->charged_seconds + first_search};
}

}  // namespace

EpisodeResult run_streaming_episode(const StreamingRun& streaming, World& world, std::uint64_t seed,
                                    const DecisionBudget& budget, DecisionTimer* timer,
                                    const std::optional<LiveRun>& live) {
  world.begin_episode(seed);
  const Clock& clock = clock_of(world);
  std::optional<FirstSkeleton> first = first_skeleton(streaming, world, clock);
  if (!first) return EpisodeResult{};  // no skeleton at all: a failure without a decision
  Arrivals arrivals{&streaming, &world, streaming.max_skeletons > 1, 0, 1};
  const bool keep_problem = streaming.keep_problem || (live && live->keep_timeline);
  EpisodeResult result;
  std::shared_ptr<const Problem> problem;
  if (streaming.make_concurrent_allocator) {
    ConcurrentSession session(first->problem.with_acting(Acting::concurrent), streaming.make_concurrent_allocator,
                              stream_seed(seed, 1), live ? &clock : nullptr, live ? live->options : LiveOptions{});
    session.expect_more_skeletons(arrivals.open);
    if (live) session.charge_outside(first->charged_seconds);
    result = drive_concurrent(session, world, timer, live, &arrivals);
    result.skeletons = arrivals.found;
    if (keep_problem) problem = std::make_shared<const Problem>(session.problem());
  } else {
    Session session(std::move(first->problem), streaming.make_allocator, stream_seed(seed, 1), live ? &clock : nullptr,
                    live ? live->options : LiveOptions{});
    session.expect_more_skeletons(arrivals.open);
    if (live) session.charge_outside(first->charged_seconds);
    result = drive(session, world, budget, timer, live, &arrivals);
    if (keep_problem) problem = std::make_shared<const Problem>(session.problem());
  }
  result.problem = std::move(problem);
  return result;
}

EpisodeResult run_concurrent_episode(const ConcurrentMdp& mdp, ConcurrentAllocator& allocator, World& world,
                                     std::uint64_t seed, DecisionTimer* timer, const std::optional<LiveRun>& live) {
  world.begin_episode(seed);
  if (!live) {
    ConcurrentSession session(mdp, allocator, stream_seed(seed, 1));
    return drive_concurrent(session, world, timer, live);
  }
  ConcurrentSession session(mdp, allocator, stream_seed(seed, 1), clock_of(world), live->options);
  return drive_concurrent(session, world, timer, live);
}

std::size_t LatencyHistogram::bucket_of(std::uint64_t nanoseconds) noexcept {
  constexpr std::uint64_t kExact = std::uint64_t{1} << kSubBits;  // below it, one bucket per value
  if (nanoseconds < kExact) return static_cast<std::size_t>(nanoseconds);
  const int exponent = static_cast<int>(std::bit_width(nanoseconds)) - 1;  // >= kSubBits
  const std::uint64_t sub = (nanoseconds >> (exponent - kSubBits)) - kExact;
  return static_cast<std::size_t>((static_cast<std::uint64_t>(exponent - kSubBits + 1) << kSubBits) + sub);
}

double LatencyHistogram::middle_of(std::size_t bucket) noexcept {
  constexpr std::size_t kExact = std::size_t{1} << kSubBits;
  if (bucket < kExact) return static_cast<double>(bucket);
  const int shift = static_cast<int>(bucket >> kSubBits) - 1;  // the bucket's width is 2^shift
  const double low = std::ldexp(static_cast<double>(kExact + (bucket & (kExact - 1))), shift);
  return low + (std::ldexp(1.0, shift) - 1) / 2;
}

void LatencyHistogram::add(std::int64_t nanoseconds) noexcept {
  const std::int64_t value = std::max<std::int64_t>(nanoseconds, 0);
  ++counts_[bucket_of(static_cast<std::uint64_t>(value))];
  ++count_;
  total_ += static_cast<double>(value);
  max_ = std::max(max_, value);
}

void LatencyHistogram::merge(const LatencyHistogram& other) noexcept {
  for (std::size_t i = 0; i < kBuckets; ++i) counts_[i] += other.counts_[i];
  count_ += other.count_;
  total_ += other.total_;
  max_ = std::max(max_, other.max_);
}

LatencySummary LatencyHistogram::summary() const {
  LatencySummary summary;
  summary.decisions = count_;
  if (count_ == 0) return summary;
  const auto at = [&](double quantile) {
    // Rounded half up (the value is never negative).
    const auto rank = static_cast<std::uint64_t>(std::floor(quantile * static_cast<double>(count_ - 1) + 0.5));
    std::uint64_t below = 0;
    for (std::size_t bucket = 0; bucket < kBuckets; ++bucket) {
      below += counts_[bucket];
      if (below > rank) return std::min(middle_of(bucket), static_cast<double>(max_)) / 1000.0;
    }
    return static_cast<double>(max_) / 1000.0;
  };
  summary.mean_us = total_ / static_cast<double>(count_) / 1000.0;
  summary.median_us = at(0.5);
  summary.p99_us = at(0.99);
  summary.max_us = static_cast<double>(max_) / 1000.0;
  return summary;
}

namespace {

// What a rank's threads found, merged: the part of a MonteCarloResult that ranks exchange.
struct RankPart {
  std::uint64_t successes = 0;
  RewardSum rewards;
  std::uint64_t model_successes = 0;
  std::uint64_t model_undecided = 0;
  LiveNanoseconds live_nanoseconds;
  LatencyHistogram decisions;
  LatencyHistogram episode_totals;
  Statistics statistics;
  Statistics world_statistics;

  void merge(const RankPart& other) {
    successes += other.successes;
    rewards.add(other.rewards);
    model_successes += other.model_successes;
    model_undecided += other.model_undecided;
    live_nanoseconds.add(other.live_nanoseconds);
    decisions.merge(other.decisions);
    episode_totals.merge(other.episode_totals);
    statistics.merge(other.statistics);
    world_statistics.merge(other.world_statistics);
  }
};

void pack_statistics(BytePacker& packer, const Statistics& statistics) {
  packer.put<std::uint64_t>(statistics.counters().size());
  for (const Statistics::Counter& counter : statistics.counters()) {
    packer.put_string(counter.name);
    packer.put(counter.value);
    packer.put(counter.merge);
  }
}

Statistics unpack_statistics(ByteUnpacker& unpacker) {
  Statistics statistics;
  for (auto count = unpacker.get<std::uint64_t>(); count > 0; --count) {
    const std::string name = unpacker.get_string();
    const auto value = unpacker.get<double>();
    statistics.add(name, value, unpacker.get<Statistics::Merge>());
  }
  return statistics;
}

// An episode's result as ranks exchange it (all but `problem`, which stays with its rank).
void pack_episode(BytePacker& packer, std::uint64_t episode, const EpisodeResult& result) {
  packer.put(episode);
  packer.put(result.status);
  packer.put(result.solution);
  packer.put(result.reward);
  packer.put(result.steps_used);
  packer.put(result.decisions);
  packer.put(result.live);
  packer.put(result.model_status);
  packer.put_vector(result.timeline);
  packer.put(result.skeletons);
  packer.put_vector(result.executions);
}

EpisodeResult unpack_episode(ByteUnpacker& unpacker, std::uint64_t& episode) {
  episode = unpacker.get<std::uint64_t>();
  EpisodeResult result;
  result.status = unpacker.get<Status>();
  result.solution = unpacker.get<int>();
  result.reward = unpacker.get<double>();
  result.steps_used = unpacker.get<Steps>();
  result.decisions = unpacker.get<int>();
  result.live = unpacker.get<LiveTotals>();
  result.model_status = unpacker.get<Status>();
  result.timeline = unpacker.get_vector<LiveStep>();
  result.skeletons = unpacker.get<int>();
  result.executions = unpacker.get_vector<LiveExecution>();
  return result;
}

// Merges this rank's part with every other rank's, in rank order (so that every rank holds the
// same totals), and hands the other ranks' episode results (`episodes`: this rank's, packed with
// pack_episode) to `on_episode`.
void merge_ranks(const Ranks& ranks, RankPart& part, const std::string& episodes, const MonteCarloOptions& options) {
  BytePacker packer;
  packer.put(part.successes);
  packer.put(part.rewards);
  packer.put(part.model_successes);
  packer.put(part.model_undecided);
  packer.put(part.live_nanoseconds);
  packer.put(part.decisions);
  packer.put(part.episode_totals);
  pack_statistics(packer, part.statistics);
  pack_statistics(packer, part.world_statistics);
  packer.put_string(episodes);
  const std::vector<std::string> parts = ranks.all_gather(packer.bytes());
  RankPart merged;
  for (std::size_t r = 0; r < parts.size(); ++r) {
    ByteUnpacker unpacker(parts[r]);
    RankPart other;
    other.successes = unpacker.get<std::uint64_t>();
    other.rewards = unpacker.get<RewardSum>();
    other.model_successes = unpacker.get<std::uint64_t>();
    other.model_undecided = unpacker.get<std::uint64_t>();
    other.live_nanoseconds = unpacker.get<LiveNanoseconds>();
    other.decisions = unpacker.get<LatencyHistogram>();
    other.episode_totals = unpacker.get<LatencyHistogram>();
    other.statistics = unpack_statistics(unpacker);
    other.world_statistics = unpack_statistics(unpacker);
    merged.merge(other);
    const std::string results = unpacker.get_string();
    if (!options.on_episode || static_cast<int>(r) == ranks.rank()) continue;
    ByteUnpacker episode_unpacker(results);
    while (!episode_unpacker.done()) {
      std::uint64_t episode = 0;
      const EpisodeResult result = unpack_episode(episode_unpacker, episode);
      options.on_episode(episode, result);
    }
  }
  part = std::move(merged);
}

// The thread's allocator from `allocators`.
void equip(ThreadRun& run, const AllocatorFactory& allocators) { run.allocator = allocators(); }
void equip(ThreadRun& run, const ConcurrentAllocatorFactory& allocators) { run.concurrent_allocator = allocators(); }

// Runs the episodes of run_episodes, run_streaming_episodes and run_concurrent_episodes on threads
// (this rank's share of them when options.ranks splits the run): `run_one(run, seed)` runs one
// episode with the thread's world (and allocator, when `allocators` is given).
template <class Factory, class RunOne>
MonteCarloResult run_many(const WorldFactory& worlds, const Factory* allocators, const MonteCarloOptions& options,
                          const RunOne& run_one) {
  const auto started = std::chrono::steady_clock::now();
  const bool split = split_over_ranks(options.ranks);
  // The units handed out are whole sequences (one episode each unless sequence_length says more).
  const std::uint64_t length = options.sequence_length;
  if (length < 1 || options.episodes % length != 0) {
    throw UsageError("episodes in sequences: " + std::to_string(options.episodes) + " episodes are not sequences of " +
                     std::to_string(length));
  }
  const RankUnits mine = rank_units(options.episodes / length, options.ranks);
  const std::uint64_t count = mine.count;
  // Episodes are handed out in blocks: the hand-out and the progress report cost little even
  // when an episode takes a fraction of a microsecond. Short runs (often of long episodes,
  // against a real planner) get smaller blocks, so that every thread has some.
  std::vector<ThreadRun> runs(worker_count(count, options.threads));
  const std::uint64_t block =
      std::clamp<std::uint64_t>(count / (8 * runs.size()), 1, std::max<std::uint64_t>(1, 256 / length));
  std::uint64_t done = 0;  // episodes finished, guarded by progress_mutex
  std::mutex progress_mutex;
  // Split runs: this rank's episode results, packed for the other ranks' on_episode.
  std::string packed_episodes;
  std::mutex packed_mutex;
  for_each_block(count, options.threads, block, [&](unsigned thread) {
    ThreadRun& run = runs[thread];
    if (allocators != nullptr) equip(run, *allocators);
    run.world = worlds();
    return [&](std::uint64_t begin, std::uint64_t end) {
      for (std::uint64_t local = 0; local < (end - begin) * length; ++local) {
        const std::uint64_t episode = mine.unit(begin + local / length) * length + local % length;
        if (options.stop && options.stop()) throw Cancelled("episodes stopped at the caller's request");
        if (options.before_episode) options.before_episode(episode, *run.world);
        const EpisodeResult result = run_one(run, stream_seed(options.seed, episode));
        if (result.status == Status::success) ++run.successes;
        run.rewards.add(result.reward);
        if (options.live) {
          run.live_nanoseconds.add(result.live);
          if (result.model_status == Status::success) ++run.model_successes;
          if (result.model_status == Status::running) ++run.model_undecided;
        }
        if (options.on_episode) {
          options.on_episode(episode, result);
          if (split) {
            BytePacker packer;
            pack_episode(packer, episode, result);
            const std::lock_guard lock(packed_mutex);
            packed_episodes += packer.bytes();
          }
        }
        if (options.time_decisions) run.timer.end_episode();
      }
      const std::uint64_t episodes_done = (end - begin) * length;
      if (options.progress) {
        // Counted under the lock that orders the reports, so that they never go backwards.
        const std::lock_guard lock(progress_mutex);
        done += episodes_done;
        options.progress(done, count * length);
      }
    };
  });

  RankPart part;
  for (ThreadRun& run : runs) {
    part.successes += run.successes;
    part.rewards.add(run.rewards);
    part.decisions.merge(run.timer.decisions);
    part.episode_totals.merge(run.timer.episodes);
    if (run.allocator) run.allocator->collect_statistics(part.statistics);
    if (run.concurrent_allocator) run.concurrent_allocator->collect_statistics(part.statistics);
    if (run.world) run.world->collect_statistics(part.world_statistics);
    part.live_nanoseconds.add(run.live_nanoseconds);
    part.model_successes += run.model_successes;
    part.model_undecided += run.model_undecided;
  }
  if (split) merge_ranks(*options.ranks, part, packed_episodes, options);

  MonteCarloResult result;
  result.episodes = options.episodes;
  result.successes = part.successes;
  result.statistics = std::move(part.statistics);
  result.world_statistics = std::move(part.world_statistics);
  result.model_successes = part.model_successes;
  result.model_undecided = part.model_undecided;
  if (options.episodes > 0) result.live_mean = part.live_nanoseconds.mean(options.episodes);
  result.success_rate =
      options.episodes == 0 ? 0.0 : static_cast<double>(result.successes) / static_cast<double>(options.episodes);
  result.ci95 = ci95_half_width(result.success_rate, options.episodes);
  const MeanInterval rewards =
      mean_interval_of_units(static_cast<double>(part.rewards.units), static_cast<double>(part.rewards.square_units),
                             static_cast<double>(options.episodes));
  result.mean_reward = rewards.mean;
  result.reward_ci95 = rewards.ci95;
  result.decision_time = part.decisions.summary();
  result.episode_decision_time = part.episode_totals.summary();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace

MonteCarloResult run_episodes(const Mdp& mdp, const WorldFactory& worlds, const AllocatorFactory& allocators,
                              const MonteCarloOptions& options) {
  return run_many(worlds, &allocators, options, [&](ThreadRun& run, std::uint64_t seed) {
    return run_episode(mdp, *run.allocator, *run.world, seed, options.decision_budget,
                       options.time_decisions ? &run.timer : nullptr, options.live);
  });
}

MonteCarloResult run_streaming_episodes(const StreamingRun& streaming, const WorldFactory& worlds,
                                        const MonteCarloOptions& options) {
  return run_many(worlds, static_cast<const AllocatorFactory*>(nullptr), options,
                  [&](ThreadRun& run, std::uint64_t seed) {
                    return run_streaming_episode(streaming, *run.world, seed, options.decision_budget,
                                                 options.time_decisions ? &run.timer : nullptr, options.live);
                  });
}

MonteCarloResult run_concurrent_episodes(const ConcurrentMdp& mdp, const WorldFactory& worlds,
                                         const ConcurrentAllocatorFactory& allocators,
                                         const MonteCarloOptions& options) {
  return run_many(worlds, &allocators, options, [&](ThreadRun& run, std::uint64_t seed) {
    return run_concurrent_episode(mdp, *run.concurrent_allocator, *run.world, seed,
                                  options.time_decisions ? &run.timer : nullptr, options.live);
  });
}

}  // namespace ontime
