// Speed of the domains (docs/domains.md): one collision check, and one refinement of each action
// in the deterministic checks unit, as the collection runs it (slices of one step, cut off after
// the deadline). Navigation's target — 1,000 trials of every action of its tree within 10 minutes
// on 2 cores — needs 15,000 refinements in 1,200 core-seconds, at most 80 ms per refinement on
// average; manipulation's — within 30 minutes — 36,000 refinements in 3,600 core-seconds, at most
// 100 ms. For manipulation also one IK solve, whose cost sets `planner.ik_checks` (the checks an
// IK solve counts as). Run a Release build:
//   build/ontime_domains_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <string>

#include "ontime/domains/collection.hpp"
#include "ontime/domains/manipulation.hpp"
#include "ontime/domains/manipulation_collision.hpp"
#include "ontime/domains/navigation.hpp"
#include "ontime/domains/navigation_collision.hpp"
#include "ontime/domains/navigation_features.hpp"
#include "ontime/domains/predict.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/domains/task_planner.hpp"
#include "ontime/util/random.hpp"

namespace {

const ontime::domains::NavigationDomain& office() {
  static const ontime::domains::NavigationDomain domain(
      ontime::domains::load_navigation_world(std::string(ONTIME_SOURCE_DIR) + "/data/domains/navigation.json"));
  return domain;
}

void BM_NavigationCollisionCheck(benchmark::State& bench) {
  const auto& world = office().world();
  const ontime::domains::NavigationCollision collision(world, world.robot.clearance);
  ontime::SplitMix64 random(1);
  const auto bounds = world.bounds();
  std::vector<ontime::domains::Pose> poses;
  for (int i = 0; i < 4096; ++i) {
    poses.push_back({bounds[0] + (bounds[2] - bounds[0]) * ontime::uniform01(random),
                     bounds[1] + (bounds[3] - bounds[1]) * ontime::uniform01(random),
                     6.28 * ontime::uniform01(random)});
  }
  std::size_t next = 0;
  for (auto _ : bench) {
    benchmark::DoNotOptimize(collision.collides(poses[next]));
    next = (next + 1) & 4095;
  }
}
BENCHMARK(BM_NavigationCollisionCheck);

// One refinement of the action with index range(0) in the domain's skeleton tree, from the start
// or from fallback starts, a fresh seed each time, in slices of one step of the world file's
// collection settings, cut off at its deadline; reports checks per refinement and found share.
template <class World>
void refinement_benchmark(benchmark::State& bench, const ontime::domains::Domain& domain, const World& world) {
  const auto tree = ontime::domains::skeleton_tree(domain.skeletons());
  const auto& node = tree.at(static_cast<std::size_t>(bench.range(0)));
  const auto& defaults = world.collection;
  const ontime::domains::EffortSettings effort{ontime::domains::EffortUnit::collision_checks,
                                               defaults.checks_per_second};
  std::uint64_t seed = 0, checks = 0, found = 0;
  for (auto _ : bench) {
    ++seed;
    const auto start = node.parent < 0 ? domain.initial_configuration() : domain.fallback_start(node.action, seed);
    const auto refinement = domain.refine(node.action, start, seed, effort);
    for (int step = 1; step <= defaults.deadline; ++step) {
      if (refinement->advance(step * defaults.step_seconds) == ontime::domains::RefinementStatus::found) {
        ++found;
        break;
      }
    }
    checks += refinement->effort().checks();
  }
  bench.counters["checks"] = benchmark::Counter(static_cast<double>(checks), benchmark::Counter::kAvgIterations);
  bench.counters["found"] = benchmark::Counter(static_cast<double>(found), benchmark::Counter::kAvgIterations);
  bench.SetLabel(node.action);
}

void BM_NavigationRefinement(benchmark::State& bench) { refinement_benchmark(bench, office(), office().world()); }
BENCHMARK(BM_NavigationRefinement)->DenseRange(0, 14)->Unit(benchmark::kMillisecond);

const ontime::domains::ManipulationDomain& kitchen() {
  static const ontime::domains::ManipulationDomain domain(
      ontime::domains::load_manipulation_world(std::string(ONTIME_SOURCE_DIR) + "/data/domains/manipulation.json"));
  return domain;
}

// Random arm configurations with the base in front of the shelf, among the objects.
std::vector<ontime::domains::ArmJoints> random_arms(std::size_t count) {
  ontime::SplitMix64 random(1);
  std::vector<ontime::domains::ArmJoints> arms(count);
  for (auto& arm : arms) {
    for (std::size_t j = 0; j < arm.size(); ++j) {
      const auto& joint = ontime::domains::pr2_left_arm_joints()[j];
      arm[j] = joint.lower + (joint.upper - joint.lower) * ontime::uniform01(random);
    }
  }
  return arms;
}

void BM_ManipulationCollisionCheck(benchmark::State& bench) {
  const auto& world = kitchen().world();
  const ontime::domains::Pr2Arm arm(world.robot.torso_lift);
  std::vector<ontime::domains::ObjectPose> poses;
  for (const auto& object : world.objects) poses.push_back(object.pose);
  const ontime::domains::ManipulationCollision collision(world, arm, poses, -1, ontime::domains::Transform::Identity(),
                                                         world.robot.clearance);
  const auto arms = random_arms(4096);
  const ontime::domains::Pose base{0.85, 2.75, 1.5708};
  std::size_t next = 0;
  for (auto _ : bench) {
    benchmark::DoNotOptimize(collision.collides(base, arms[next]));
    next = (next + 1) & 4095;
  }
}
BENCHMARK(BM_ManipulationCollisionCheck);

// One IK solve from a random initial guess to the tool frame of another random configuration
// (about a third of them converge within the limits).
void BM_ManipulationInverseKinematics(benchmark::State& bench) {
  const ontime::domains::Pr2Arm arm(kitchen().world().robot.torso_lift);
  const auto targets = random_arms(4096);
  const auto guesses = random_arms(4097);
  std::size_t next = 0, found = 0;
  for (auto _ : bench) {
    found += arm.inverse(arm.tool(targets[next]), guesses[next + 1]).has_value() ? 1 : 0;
    next = (next + 1) & 4095;
  }
  bench.counters["found"] = benchmark::Counter(static_cast<double>(found), benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_ManipulationInverseKinematics);

void BM_ManipulationRefinement(benchmark::State& bench) { refinement_benchmark(bench, kitchen(), kitchen().world()); }
BENCHMARK(BM_ManipulationRefinement)->DenseRange(0, 35)->Unit(benchmark::kMillisecond);

}  // namespace

// The task planner of `ontime tamp` on the generated 30-room building: the first `range(0)` room
// paths from start to goal in order of length, computed from scratch (a new factory each time).
void BM_RoomPathsBuilding(benchmark::State& bench) {
  static const ontime::domains::NavigationWorld world =
      ontime::domains::load_navigation_world(std::string(ONTIME_SOURCE_DIR) + "/data/domains/building-6x5.json");
  const auto paths = static_cast<int>(bench.range(0));
  for (auto _ : bench) {
    const auto planner = ontime::domains::room_path_planners(world, paths)();
    for (int k = 0; k < paths; ++k) benchmark::DoNotOptimize(planner->next());
  }
}
BENCHMARK(BM_RoomPathsBuilding)->Arg(1)->Arg(16)->Arg(64)->Unit(benchmark::kMicrosecond);

// `ontime predict` on the 30-room building: features and a conditional model's PMFs for its 78
// doorway moves (issue target: 10 ms). The model is fitted once, on drawn rows (its cost per
// prediction does not depend on what it learned): 11 features, horizon 45.
void BM_PredictBuilding(benchmark::State& bench) {
  const std::string world = std::string(ONTIME_SOURCE_DIR) + "/data/domains/building-6x5.json";
  const ontime::domains::LoadedDomain building = ontime::domains::load_domain("navigation", world);
  ontime::ConditionalData data;
  data.step_seconds = building.defaults.collection.step_seconds;
  data.feature_count = ontime::domains::navigation_feature_names().size();
  ontime::SplitMix64 random(1);
  for (int i = 0; i < 2000; ++i) {
    for (std::size_t f = 0; f < data.feature_count; ++f) data.features.push_back(ontime::uniform01(random));
    data.found.push_back(ontime::uniform01(random) < 0.8 ? 1 : 0);
    data.planning.push_back(1 + static_cast<ontime::Steps>(44 * ontime::uniform01(random)));
    data.execution_seconds.push_back(data.found.back() != 0 ? 3 + 10 * ontime::uniform01(random) : 0.0);
    data.worlds.emplace_back("drawn");
    data.actions.emplace_back("a");
  }
  ontime::ConditionalFitOptions options;
  options.kind = bench.range(0) == 0 ? "hazard" : "boosted";
  options.feature_names = ontime::domains::navigation_feature_names();
  options.horizon = 45;
  const auto model = ontime::fit_conditional_model(data, options);
  bench.SetLabel(options.kind);
  for (auto _ : bench) {
    benchmark::DoNotOptimize(ontime::domains::predict_instance(*building.domain, building.defaults, *model,
                                                               ontime::domains::PredictOptions{}));
  }
}
// Argument 0: a hazard model; 1: a boosted one (100 trees of depth 3 in each of three boosters).
BENCHMARK(BM_PredictBuilding)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
