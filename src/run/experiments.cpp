#include "ontime/run/experiments.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "ontime/allocators/optimal.hpp"
#include "ontime/run/simulator.hpp"
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
    MonteCarloOptions options;
    options.decision_budget = budget;
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
    MonteCarloResult result = run_monte_carlo(mdp, factory, options);
    done_ += settings_.episodes;
    return result;
  }

 private:
  const StudySettings& settings_;
  std::uint64_t total_;
  std::uint64_t done_ = 0;
};

// The two kinds of a study, checked by capability.
struct StudyPair {
  AllocatorFactory searcher;
  AllocatorFactory reference;
};

double optimum_of(const Mdp& mdp, const ParameterValues& values) {
  return OptimalSolver(mdp, max_states_of(values)).solve(mdp.start());
}

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

StudyPair make_pair(const Mdp& mdp, const StudySettings& settings) {
  check_study_kinds(settings);
  const AllocatorRegistry& registry = allocator_registry();
  return {registry.make_factory(settings.searcher, mdp, settings.parameters),
          registry.make_factory(settings.reference, mdp, settings.parameters)};
}

// The reference's mean time per decision, as rank 0 measured it when the study is split over
// ranks (each rank would otherwise give the searcher its own budget).
double reference_decision_seconds(const Mdp& mdp, const AllocatorFactory& reference, const StudySettings& settings) {
  const double seconds = mean_decision_seconds(mdp, reference, settings.seed);
  if (!split_over_ranks(settings.ranks)) return seconds;
  BytePacker packer;
  packer.put(seconds);
  return ByteUnpacker(settings.ranks->all_gather(packer.bytes()).front()).get<double>();
}

}  // namespace

double mean_decision_seconds(const Mdp& mdp, const AllocatorFactory& factory, std::uint64_t seed,
                             std::uint64_t episodes) {
  const std::unique_ptr<Allocator> allocator = factory();
  std::vector<State> states;
  StateRecorder recorder(*allocator, states);
  HiddenWorld world(mdp.problem(), seed);
  for (std::uint64_t episode = 0; episode < episodes; ++episode) {
    run_episode(mdp, recorder, world, stream_seed(seed, episode));
  }
  if (states.empty()) return 0.0;
  // Enough passes over the recorded states for the clock's resolution not to matter.
  constexpr std::size_t kMinimumDecisions = 2'000'000;
  const std::size_t passes = std::max<std::size_t>(1, kMinimumDecisions / states.size());
  allocator->begin_episode(seed);
  int sink = 0;
  const auto started = std::chrono::steady_clock::now();
  for (std::size_t pass = 0; pass < passes; ++pass) {
    for (const State& state : states) sink += allocator->choose(state);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  volatile int keep = sink;  // the loop must not be optimised away
  (void)keep;
  return seconds / static_cast<double>(passes * states.size());
}

ComputeTimeStudy compute_time_study(const Mdp& mdp, const StudySettings& settings) {
  const StudyPair pair = make_pair(mdp, settings);
  ProgressTracker tracker(settings, 2 * settings.episodes);
  ComputeTimeStudy study;
  study.searcher = tracker.run(mdp, pair.searcher);
  study.reference = tracker.run(mdp, pair.reference);
  return study;
}

EqualTimeStudy equal_time_study(const Mdp& mdp, const StudySettings& settings) {
  const StudyPair pair = make_pair(mdp, settings);
  ProgressTracker tracker(settings, 2 * settings.episodes);
  EqualTimeStudy study;
  study.reference_decision_seconds = reference_decision_seconds(mdp, pair.reference, settings);
  study.reference = tracker.run(mdp, pair.reference);
  study.searcher = tracker.run(mdp, pair.searcher, DecisionBudget::seconds(study.reference_decision_seconds));
  return study;
}

AnytimeStudy anytime_study(const Mdp& mdp, const std::vector<double>& log10_multipliers,
                           const StudySettings& settings) {
  for (const double exponent : log10_multipliers) {
    if (!std::isfinite(exponent) || exponent < -3 || exponent > 9) {
      throw UsageError("log10 time multipliers must lie within [-3, 9]");
    }
  }
  const StudyPair pair = make_pair(mdp, settings);
  ProgressTracker tracker(settings, (log10_multipliers.size() + 1) * settings.episodes);
  AnytimeStudy study;
  study.reference_decision_seconds = reference_decision_seconds(mdp, pair.reference, settings);
  study.optimum = optimum_of(mdp, settings.parameters);
  study.reference = tracker.run(mdp, pair.reference);
  for (const double exponent : log10_multipliers) {
    AnytimePoint point;
    point.log10_multiplier = exponent;
    point.seconds_per_decision = study.reference_decision_seconds * portable_pow(10.0, exponent);
    point.searcher = tracker.run(mdp, pair.searcher, DecisionBudget::seconds(point.seconds_per_decision));
    study.points.push_back(std::move(point));
  }
  return study;
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
  for (const StudyInstance& instance : instances) {
    allocator_registry().check_memory(settings.searcher, instance.problem, settings.parameters, allocators, spelling);
    if (kind == StudyKind::anytime) {
      check_exact_work(instance.problem, max_states_of(settings.parameters), instance.source, spelling);
    }
  }
}

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
    const Mdp mdp(instances[i].problem);
    switch (kind) {
      case StudyKind::compute_time:
        rows.compute_time.push_back(compute_time_study(mdp, one));
        break;
      case StudyKind::equal_time:
        rows.equal_time.push_back(equal_time_study(mdp, one));
        break;
      case StudyKind::anytime:
        rows.anytime.push_back(anytime_study(mdp, log10_multipliers, one));
        break;
    }
  }
  return rows;
}

}  // namespace ontime
