#pragma once
// The episode runner: episodes in which an allocator decides, through a Session, which action
// gets each step of effort, and a World (world.hpp) answers. One episode at a time, or many on
// threads with their success rate and its interval, the decision latency, and the allocators'
// and the worlds' counters. Simulated evaluation (hidden sampled worlds), the computation-time
// studies and episodes against a domain's real planner all run here.
//
// Seeding, the same for every world: episode e of a run with seed S has the seed
// s_e = stream_seed(S, e); its world begins from s_e and its allocator from stream_seed(s_e, 1).
// An episode is thus the same whichever thread runs it and whatever ran before it on that
// thread, so the results do not depend on the thread count, and every episode's allocator has
// its own random stream. Nor on the number of processes: a run split over MPI ranks
// (MonteCarloOptions::ranks) gives each rank an interleaved share of the episodes (rank_units).

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/allocators/decision_budget.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/run/concurrent_session.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/world.hpp"
#include "ontime/util/ranks.hpp"
#include "ontime/util/statistics.hpp"

namespace ontime {

// Receives the duration of each decision of an episode, in nanoseconds.
class DecisionTimer {
 public:
  virtual ~DecisionTimer() = default;
  // Called once per decision, with its duration.
  virtual void record(std::int64_t nanoseconds) = 0;
};

struct EpisodeResult {
  Status status = Status::failure;
  int solution = -1;     // skeleton executed on success
  double reward = 0;     // Session::reward(): the solution's reward (1 without rewards), 0 on failure
  Steps steps_used = 0;  // steps of effort spent
  int decisions = 0;
  // Live episodes only: what the session charged, the step clock's verdict on the same calls
  // (Session::model_status), and the timeline when asked for.
  LiveTotals live;
  Status model_status = Status::running;
  std::vector<LiveStep> timeline;
  // Live episodes whose timeline is kept: the robot's executions (acting while planning, each
  // motion it started; plan-first, the plan executed after success).
  std::vector<LiveExecution> executions;
  // Streaming episodes: the skeletons found, and (when the timeline is kept, or
  // StreamingRun::keep_problem) the episode's final problem, whose action and skeleton indices the
  // timeline and `attempts` use.
  int skeletons = 0;
  std::shared_ptr<const Problem> problem;
  // What the episode saw of each action (Session::attempts), by action index.
  std::vector<ActionAttempt> attempts;
};

// Live episodes (session.hpp): each a live session on its world's clock (World::clock(), else
// the steady clock).
struct LiveRun {
  LiveOptions options;
  bool keep_timeline = false;  // copy each episode's timeline into its EpisodeResult
};

// Runs the episode with seed `seed` (see above): every decision within `budget` (unset: the
// allocator's own), each timed when `timer` is given; a live episode when `live` is set. An
// idle step (a skeleton with nothing left to refine) is reported without asking the world.
EpisodeResult run_episode(const Mdp& mdp, Allocator& allocator, World& world, std::uint64_t seed,
                          const DecisionBudget& budget = {}, DecisionTimer* timer = nullptr,
                          const std::optional<LiveRun>& live = std::nullopt);

// One episode acting while planning (SPEC §10) with seed `seed`, seeded as run_episode: the
// allocator's moves through a ConcurrentSession (concurrent_session.hpp), its steps in `world`.
// Every move, a start or a step, is a decision (timed when `timer` is given).
EpisodeResult run_concurrent_episode(const ConcurrentMdp& mdp, ConcurrentAllocator& allocator, World& world,
                                     std::uint64_t seed, DecisionTimer* timer = nullptr,
                                     const std::optional<LiveRun>& live = std::nullopt);

// Episodes whose skeletons stream in from the world (World::next_skeleton), as a task planner
// running alongside finds them. Each episode's session owns its problem (session.hpp): it begins
// once the first skeleton is found (a live episode is charged that search, its clock's time and
// the skeleton's charged seconds), takes the next skeleton after every `period` steps, and at
// once whenever no skeleton found so far can still succeed, up to `max_skeletons`; the
// allocator is made anew for each (Session::add_skeleton). An episode whose world finds no
// skeleton at all fails with no decision.
struct StreamingRun {
  std::string name = "streaming";  // of the episodes' problems
  Steps deadline = 1;
  double step_seconds = 1;
  Session::AllocatorMaker make_allocator;
  // Set: the robot acts while planning (SPEC §10), each episode an owning ConcurrentSession with this
  // maker's allocators. After every start the skeletons not through what the robot executed
  // retire, and the world is told the executed prefix (World::commit), so that its task planner
  // streams only skeletons through it.
  ConcurrentSession::AllocatorMaker make_concurrent_allocator;
  int period = 1;
  int max_skeletons = kMaxExactSkeletons;
  bool keep_problem = false;  // every episode's final problem in its result (the ids of its attempts)
};

// One streaming episode with seed `seed`, as run_episode.
EpisodeResult run_streaming_episode(const StreamingRun& streaming, World& world, std::uint64_t seed,
                                    const DecisionBudget& budget = {}, DecisionTimer* timer = nullptr,
                                    const std::optional<LiveRun>& live = std::nullopt);

struct MonteCarloOptions {
  std::uint64_t episodes = 10'000;
  std::uint64_t seed = 1;
  unsigned threads = 0;        // 0: one per hardware thread
  bool time_decisions = true;  // measure each decision (adds ~40 ns of clock reads)
  // Passed to every decision (unset: each allocator's own budget); all threads share it, so a
  // stop condition must be thread-safe.
  DecisionBudget decision_budget;
  // Called now and then with the number of episodes done (from one thread at a time).
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
  // Checked before each episode, from every thread (so it must be thread-safe): once it returns
  // true, no episode starts and the run ends by throwing Cancelled.
  std::function<bool()> stop;
  // Live episodes.
  std::optional<LiveRun> live;
  // Called with every episode's result (from any thread, so it must be thread-safe; episodes
  // are numbered 0 .. episodes - 1). In a run split over ranks, every rank gets every episode:
  // its own as they end, the other ranks' (without `problem`) once all have ended.
  std::function<void(std::uint64_t episode, const EpisodeResult& result)> on_episode;
  // Episodes in sequences of this many consecutive ones (`episodes` must be a multiple of it):
  // each sequence runs in order on one thread (and one rank), so that what one episode taught
  // (on_episode) can shape the next (before_episode): a robot that learns across the episodes of
  // one world (online_belief.hpp). 1: every episode on its own. Seeds and results stay those of
  // the episode's index, so the numbers do not depend on the thread or rank count.
  std::uint64_t sequence_length = 1;
  // Called on the thread that runs it, just before episode `episode` begins, with that thread's
  // world (the one `worlds` made for it).
  std::function<void(std::uint64_t episode, World& world)> before_episode;
  // When set, the episodes are split over these ranks (ranks.hpp): each runs its share on its
  // own threads, then they exchange their results, and every rank returns the same totals (the
  // numbers of one process, latencies aside). Every rank must make the same call. `progress`
  // counts the rank's own share. Sequences are not split: each rank takes whole ones.
  const Ranks* ranks = nullptr;
};

struct LatencySummary {
  std::uint64_t decisions = 0;
  double mean_us = 0, median_us = 0, p99_us = 0, max_us = 0;
};

// Durations in nanoseconds summarised in fixed memory (about 29 KiB), however many are added:
// a log-scale histogram with 64 buckets per power of two. The count, mean and maximum are exact;
// a quantile is exact below 64 ns and otherwise the middle of the bucket holding it, within
// 1/128 (0.8%) of the true sample value. Histograms of several threads merge exactly.
class LatencyHistogram {
 public:
  // Adds one duration; a negative one counts as 0.
  void add(std::int64_t nanoseconds) noexcept;
  // Adds every duration of `other`, as if each had been added here.
  void merge(const LatencyHistogram& other) noexcept;
  // The quantile of rank round(q (n - 1)) of the n durations added, as LatencySummary's.
  LatencySummary summary() const;

 private:
  static constexpr int kSubBits = 6;  // 2^6 buckets per power of two
  static constexpr std::size_t kBuckets = (64 - kSubBits) << kSubBits;
  static std::size_t bucket_of(std::uint64_t nanoseconds) noexcept;
  static double middle_of(std::size_t bucket) noexcept;
  std::array<std::uint64_t, kBuckets> counts_{};
  std::uint64_t count_ = 0;
  double total_ = 0;
  std::int64_t max_ = 0;
};

struct MonteCarloResult {
  std::uint64_t episodes = 0;
  std::uint64_t successes = 0;
  double success_rate = 0;
  double ci95 = 0;  // half-width: 1.96 * sqrt(r (1 - r) / N)  (SPEC §4)
  // The mean reward of an episode (SPEC §8; the success rate, to within 2^-32, without rewards)
  // and its 95% half-width.
  double mean_reward = 0;
  double reward_ci95 = 0;
  LatencySummary decision_time;
  LatencySummary episode_decision_time;  // total decision time of each episode (meta-level cost)
  double seconds = 0;                    // wall-clock time of the whole run
  Statistics statistics;                 // the allocators' counters, merged over threads
  Statistics world_statistics;           // the worlds' counters, merged over threads
  LiveTotals live_mean;                  // live runs: the mean charges of an episode
  std::uint64_t model_successes = 0;     // live runs: successes by the step clock
  std::uint64_t model_undecided = 0;     // live runs: episodes the step clock had not decided
};

// Runs `options.episodes` episodes, seeded as above. Each thread gets its own allocator from
// `allocators` and its own world from `worlds`. Throws Cancelled when `options.stop` trips.
MonteCarloResult run_episodes(const Mdp& mdp, const WorldFactory& worlds, const AllocatorFactory& allocators,
                              const MonteCarloOptions& options);

// Streaming episodes (see StreamingRun), seeded and parallel as run_episodes; the allocators
// belong to the episodes' sessions, so `statistics` stays empty.
MonteCarloResult run_streaming_episodes(const StreamingRun& streaming, const WorldFactory& worlds,
                                        const MonteCarloOptions& options);

// Episodes acting while planning (run_concurrent_episode), seeded and parallel as run_episodes.
// The decision budget is not used (no concurrent allocator is anytime yet). Live episodes
// (MonteCarloOptions::live) are live ConcurrentSessions on each world's clock.
MonteCarloResult run_concurrent_episodes(const ConcurrentMdp& mdp, const WorldFactory& worlds,
                                         const ConcurrentAllocatorFactory& allocators,
                                         const MonteCarloOptions& options);

// The 95% half-width of SPEC §4 for r successes out of n.
double ci95_half_width(double rate, std::uint64_t episodes) noexcept;

}  // namespace ontime
