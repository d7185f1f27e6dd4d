#include "ontime/run/experiments.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/util/byte_packing.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/parallel.hpp"
#include "ontime/util/random.hpp"
#include "util/portable_math.hpp"

namespace ontime {
namespace {

// Records the states an allocator decides in, passing its choices through.
class StateRecorder final : public Allocator {
 public:
  StateRecorder(Allocator& inner, std::vector<State>& states) : inner_(&inner), states_(&states) {}
  std::string_view name() const noexcept override { return inner_->name(); }
  void begin_episode(std::uint64_t seed) override { inner_->begin_episode(seed); }
  int choose(const State& state) override {
    states_->push_back(state);
    return inner_->choose(state);
  }
  int choose(const State& state, const DecisionBudget& budget) override {
    states_->push_back(state);
    return inner_->choose(state, budget);
  }
  void observe(const State& before, int choice, const State& after, Status status) override {
    inner_->observe(before, choice, after, status);
  }

 private:
  Allocator* inner_;
  std::vector<State>* states_;
};

// Runs Monte Carlo episodes while reporting study-wide progress.
class ProgressTracker {
 public:
  ProgressTracker(const StudySettings& settings, std::uint64_t total) : settings_(settings), total_(total) {}

  MonteCarloResult run(const Mdp& mdp, const AllocatorFactory& factory, const DecisionBudget& budget = {}) {
    MonteCarloOptions options = options_for_run();
    options.decision_budget = budget;
    MonteCarloResult result = run_monte_carlo(mdp, factory, options);
    done_ += settings_.episodes;
    return result;
  }
  // The same acting while planning (SPEC §10): the searcher's budget is in its factory.
  MonteCarloResult run(const ConcurrentMdp& mdp, const ConcurrentAllocatorFactory& factory) {
    MonteCarloOptions options = options_for_run();
    MonteCarloResult result = run_monte_carlo(mdp, factory, options);
    done_ += settings_.episodes;
    return result;
  }

 private:
  MonteCarloOptions options_for_run() {
    MonteCarloOptions options;
    options.episodes = settings_.episodes;
    options.seed = settings_.seed;
    options.threads = settings_.threads;
    options.ranks = settings_.ranks;
    const std::uint64_t before = done_;
    if (settings_.progress) {
      options.progress = [this, before](std::uint64_t done, std::uint64_t) {
        settings_.progress(before + done, total_);
      };
    }
    return options;
  }

  const StudySettings& settings_;
  std::uint64_t total_;
  std::uint64_t done_ = 0;
};

void check_study_kinds(const StudySettings& settings) {
  const AllocatorRegistry& registry = allocator_registry();
  if (!registry.find(settings.searcher).capabilities.has(Capability::anytime)) {
    throw UsageError("the searcher of a study must be an anytime allocator (known: " +
                     fmt::format("{}", fmt::join(registry.names({Capability::anytime}), ", ")) + "), not '" +
                     settings.searcher + "'");
  }
  if (!registry.find(settings.reference).capabilities.has(Capability::stationary)) {
    throw UsageError("the reference of a study must be a stationary allocator, not '" + settings.reference + "'");
  }
}

// The reference's mean time per decision, as rank 0 measured it when the study is split over
// ranks (each rank would otherwise give the searcher its own budget).
double shared_seconds(double seconds, const StudySettings& settings) {
  if (!split_over_ranks(settings.ranks)) return seconds;
  BytePacker packer;
  packer.put(seconds);
  return ByteUnpacker(settings.ranks->all_gather(packer.bytes()).front()).get<double>();
}

// A study's factories, planning first and acting while planning (SPEC §10).
AllocatorFactory study_factory(const Mdp& mdp, const std::string& name, const ParameterValues& values) {
  return allocator_registry().make_factory(name, mdp, values);
}
ConcurrentAllocatorFactory study_factory(const ConcurrentMdp& mdp, const std::string& name,
                                         const ParameterValues& values) {
  return allocator_registry().make_concurrent_factory(name, mdp, values);
}

// The searcher within `seconds` per decision, or its own default budget (nullopt). Planning first
// the time is the budget passed with each decision, so one factory serves every time setting.
MonteCarloResult run_searcher(ProgressTracker& tracker, const Mdp& mdp, const AllocatorFactory& searcher,
                              const StudySettings&, std::optional<double> seconds) {
  return tracker.run(mdp, searcher, seconds ? DecisionBudget::seconds(*seconds) : DecisionBudget{});
}
// A concurrent allocator takes no budget with each move: the searcher of a time setting is made
// with that time as its `time-budget` parameter (and no `iterations`, as a per-decision budget
// replaces the default one).
MonteCarloResult run_searcher(ProgressTracker& tracker, const ConcurrentMdp& mdp,
                              const ConcurrentAllocatorFactory& searcher, const StudySettings& settings,
                              std::optional<double> seconds) {
  if (!seconds) return tracker.run(mdp, searcher);
  ParameterValues timed;
  for (const auto& [name, value] : settings.parameters.all()) {
    if (name != "iterations" && name != "time-budget") timed.set(name, value);
  }
  timed.set("time-budget", fmt::format("{:.17g}", *seconds));
  return tracker.run(mdp, study_factory(mdp, settings.searcher, timed));
}

double optimum_of(const Mdp& mdp, const ParameterValues& values) {
  return OptimalSolver(mdp, max_states_of(values)).solve(mdp.start());
}
double optimum_of(const ConcurrentMdp& mdp, const ParameterValues& values) {
  ConcurrentSolver solver(mdp, max_states_of(values));
  return solver.solve(mdp.start());
}

// A study's two allocators on one instance, in the acting mode of `Model` (Mdp or ConcurrentMdp).
template <class Model>
class StudyArena {
 public:
  StudyArena(const Model& mdp, const StudySettings& settings)
      : mdp_(&mdp),
        settings_(&settings),
        searcher_((check_study_kinds(settings), study_factory(mdp, settings.searcher, settings.parameters))),
        reference_(study_factory(mdp, settings.reference, settings.parameters)) {}
  MonteCarloResult reference(ProgressTracker& tracker) const { return tracker.run(*mdp_, reference_); }
  MonteCarloResult searcher(ProgressTracker& tracker, std::optional<double> seconds) const {
    return run_searcher(tracker, *mdp_, searcher_, *settings_, seconds);
  }
  double reference_seconds() const { return mean_decision_seconds(*mdp_, reference_, settings_->seed); }
  double optimum() const { return optimum_of(*mdp_, settings_->parameters); }

 private:
  const Model* mdp_;
  const StudySettings* settings_;
  decltype(study_factory(std::declval<const Model&>(), std::string(), ParameterValues())) searcher_;
  decltype(study_factory(std::declval<const Model&>(), std::string(), ParameterValues())) reference_;
};

template <class Arena>
ComputeTimeStudy compute_time(const Arena& arena, const StudySettings& settings) {
  ProgressTracker tracker(settings, 2 * settings.episodes);
  ComputeTimeStudy study;
  study.searcher = arena.searcher(tracker, std::nullopt);
  study.reference = arena.reference(tracker);
  return study;
}

template <class Arena>
EqualTimeStudy equal_time(const Arena& arena, const StudySettings& settings) {
  ProgressTracker tracker(settings, 2 * settings.episodes);
  EqualTimeStudy study;
  study.reference_decision_seconds = shared_seconds(arena.reference_seconds(), settings);
  study.reference = arena.reference(tracker);
  study.searcher = arena.searcher(tracker, study.reference_decision_seconds);
  return study;
}

template <class Arena>
AnytimeStudy anytime(const Arena& arena, const std::vector<double>& log10_multipliers, const StudySettings& settings) {
  for (const double exponent : log10_multipliers) {
    if (!std::isfinite(exponent) || exponent < -3 || exponent > 9) {
      throw UsageError("log10 time multipliers must lie within [-3, 9]");
    }
  }
  ProgressTracker tracker(settings, (log10_multipliers.size() + 1) * settings.episodes);
  AnytimeStudy study;
  study.reference_decision_seconds = shared_seconds(arena.reference_seconds(), settings);
  study.optimum = arena.optimum();
  study.reference = arena.reference(tracker);
  for (const double exponent : log10_multipliers) {
    AnytimePoint point;
    point.log10_multiplier = exponent;
    point.seconds_per_decision = study.reference_decision_seconds * portable_pow(10.0, exponent);
    point.searcher = arena.searcher(tracker, point.seconds_per_decision);
    study.points.push_back(std::move(point));
  }
  return study;
}

// Records the moves' states of a concurrent allocator, passing its moves through.
class ConcurrentStateRecorder final : public ConcurrentAllocator {
 public:
  ConcurrentStateRecorder(ConcurrentAllocator& inner, std::vector<ConcurrentState>& states)
      : inner_(&inner), states_(&states) {}
  std::string_view name() const noexcept override { return inner_->name(); }
  void begin_episode(std::uint64_t seed) override { inner_->begin_episode(seed); }
  ConcurrentMdp::Move choose(const ConcurrentState& state) override {
    states_->push_back(state);
    return inner_->choose(state);
  }
  void observe(const ConcurrentState& before, int choice, const ConcurrentState& after) override {
    inner_->observe(before, choice, after);
  }
  bool is_stationary() const noexcept override { return inner_->is_stationary(); }

 private:
  ConcurrentAllocator* inner_;
  std::vector<ConcurrentState>* states_;
};

// Times `decide` over `states` in bulk: enough passes for the clock's resolution not to matter.
template <class State, class Decide>
double seconds_per_decision(const std::vector<State>& states, Decide&& decide) {
  if (states.empty()) return 0.0;
  constexpr std::size_t kMinimumDecisions = 2'000'000;
  const std::size_t passes = std::max<std::size_t>(1, kMinimumDecisions / states.size());
  int sink = 0;
  const auto started = std::chrono::steady_clock::now();
  for (std::size_t pass = 0; pass < passes; ++pass) {
    for (const State& state : states) sink += decide(state);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  volatile int keep = sink;  // the loop must not be optimised away
  (void)keep;
  return seconds / static_cast<double>(passes * states.size());
}

// One episode in the acting mode of the model, for recording.
void run_recorded(const Mdp& mdp, Allocator& allocator, World& world, std::uint64_t seed) {
  run_episode(mdp, allocator, world, seed);
}
void run_recorded(const ConcurrentMdp& mdp, ConcurrentAllocator& allocator, World& world, std::uint64_t seed) {
  run_concurrent_episode(mdp, allocator, world, seed);
}
int decision_sum(int choice) { return choice; }
int decision_sum(const ConcurrentMdp::Move& move) { return move.start + move.refine; }

// The mean seconds of one decision over the states `episodes` of the allocator's own episodes
// meet (recorded by Recorder), timed in bulk.
template <class Recorder, class Model, class Factory>
double recorded_decision_seconds(const Model& mdp, const Factory& factory, std::uint64_t seed, std::uint64_t episodes) {
  const auto allocator = factory();
  std::vector<std::decay_t<decltype(mdp.start())>> states;
  Recorder recorder(*allocator, states);
  HiddenWorld world(mdp.problem(), seed);
  for (std::uint64_t episode = 0; episode < episodes; ++episode) {
    run_recorded(mdp, recorder, world, stream_seed(seed, episode));
  }
  allocator->begin_episode(seed);
  return seconds_per_decision(states, [&](const auto& state) { return decision_sum(allocator->choose(state)); });
}

}  // namespace

double mean_decision_seconds(const Mdp& mdp, const AllocatorFactory& factory, std::uint64_t seed,
                             std::uint64_t episodes) {
  return recorded_decision_seconds<StateRecorder>(mdp, factory, seed, episodes);
}

double mean_decision_seconds(const ConcurrentMdp& mdp, const ConcurrentAllocatorFactory& factory, std::uint64_t seed,
                             std::uint64_t episodes) {
  return recorded_decision_seconds<ConcurrentStateRecorder>(mdp, factory, seed, episodes);
}

ComputeTimeStudy compute_time_study(const Mdp& mdp, const StudySettings& settings) {
  return compute_time(StudyArena<Mdp>(mdp, settings), settings);
}

ComputeTimeStudy compute_time_study(const ConcurrentMdp& mdp, const StudySettings& settings) {
  return compute_time(StudyArena<ConcurrentMdp>(mdp, settings), settings);
}

EqualTimeStudy equal_time_study(const Mdp& mdp, const StudySettings& settings) {
  return equal_time(StudyArena<Mdp>(mdp, settings), settings);
}

EqualTimeStudy equal_time_study(const ConcurrentMdp& mdp, const StudySettings& settings) {
  return equal_time(StudyArena<ConcurrentMdp>(mdp, settings), settings);
}

AnytimeStudy anytime_study(const Mdp& mdp, const std::vector<double>& log10_multipliers,
                           const StudySettings& settings) {
  return anytime(StudyArena<Mdp>(mdp, settings), log10_multipliers, settings);
}

AnytimeStudy anytime_study(const ConcurrentMdp& mdp, const std::vector<double>& log10_multipliers,
                           const StudySettings& settings) {
  return anytime(StudyArena<ConcurrentMdp>(mdp, settings), log10_multipliers, settings);
}

StudyKind study_kind(std::string_view name) {
  if (name == "compute-time") return StudyKind::compute_time;
  if (name == "equal-time") return StudyKind::equal_time;
  if (name == "anytime") return StudyKind::anytime;
  throw UsageError("unknown study '" + std::string(name) + "' (known: compute-time, equal-time, anytime)");
}

std::string_view to_string(StudyKind kind) noexcept {
  switch (kind) {
    case StudyKind::compute_time:
      return "compute-time";
    case StudyKind::equal_time:
      return "equal-time";
    case StudyKind::anytime:
      return "anytime";
  }
  return "";
}

void check_study_request(StudyKind kind, const std::vector<StudyInstance>& instances, const StudySettings& settings,
                         const ParameterSpelling& spelling) {
  check_study_kinds(settings);
  if (instances.empty()) throw UsageError("a study needs at least one instance");
  const std::uint64_t allocators = worker_count(settings.episodes, settings.threads);
  const AllocatorRegistry& registry = allocator_registry();
  for (const StudyInstance& instance : instances) {
    if (instance.problem.acting() == Acting::concurrent) {
      for (const std::string& name : {settings.searcher, settings.reference}) {
        if (!registry.find(name).acts_while_planning()) {
          throw UsageError(
              fmt::format("{}: allocator '{}' does not act while planning (SPEC §10) yet: it has no commit rule; {} do",
                          instance.source, name, fmt::join(registry.acting_names(), ", ")));
        }
      }
    }
    registry.check_memory(settings.searcher, instance.problem, settings.parameters, allocators, spelling);
    if (kind == StudyKind::anytime) {
      check_exact_work(instance.problem, max_states_of(settings.parameters), instance.source, spelling);
    }
  }
}

namespace {

// One instance's row of a study, planning first or acting while planning.
template <class Model>
void add_study_row(StudyRows& rows, StudyKind kind, const Model& mdp, const std::vector<double>& log10_multipliers,
                   const StudySettings& settings) {
  switch (kind) {
    case StudyKind::compute_time:
      rows.compute_time.push_back(compute_time_study(mdp, settings));
      break;
    case StudyKind::equal_time:
      rows.equal_time.push_back(equal_time_study(mdp, settings));
      break;
    case StudyKind::anytime:
      rows.anytime.push_back(anytime_study(mdp, log10_multipliers, settings));
      break;
  }
}

}  // namespace

StudyRows run_study(StudyKind kind, const std::vector<StudyInstance>& instances, const StudySettings& settings,
                    const std::vector<double>& log10_multipliers) {
  StudyRows rows;
  rows.kind = kind;
  rows.log10_multipliers = log10_multipliers;
  for (std::size_t i = 0; i < instances.size(); ++i) {
    rows.labels.push_back(instances[i].label);
    StudySettings one = settings;
    if (settings.progress) {
      one.progress = [&settings, i, count = instances.size()](std::uint64_t done, std::uint64_t total) {
        settings.progress(i * total + done, count * total);
      };
    }
    const Problem& problem = instances[i].problem;
    if (problem.acting() == Acting::concurrent) {
      add_study_row(rows, kind, ConcurrentMdp(problem), log10_multipliers, one);
    } else {
      add_study_row(rows, kind, Mdp(problem), log10_multipliers, one);
    }
  }
  return rows;
}

}  // namespace ontime
