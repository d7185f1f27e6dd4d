// Speed targets of the core (docs/performance.md): dp-rerun decision latency, exact solve
// time, Monte Carlo throughput, the Table I workload and the cost of loading large inputs
// (linear in their size: the BigO fits below report it). Run a Release build:
//   build/ontime_bench --benchmark_repetitions=10 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "ontime/ontime.hpp"

namespace {

ontime::Problem paper(int index) {
  const std::string name = index == 0 ? "figure1" : "instance" + std::to_string(index);
  return ontime::load_problem(std::string(ONTIME_SOURCE_DIR) + "/data/instances/paper/" + name + ".json");
}

// States dp-rerun actually decides in: those visited by its own episodes, in visiting order.
std::vector<ontime::State> decision_states(const ontime::Mdp& mdp, ontime::Allocator& allocator, int episodes) {
  class Recorder final : public ontime::Allocator {
   public:
    Recorder(ontime::Allocator& inner, std::vector<ontime::State>& states) : inner_(inner), states_(states) {}
    std::string_view name() const noexcept override { return "recorder"; }
    int choose(const ontime::State& state) override {
      states_.push_back(state);
      return inner_.choose(state);
    }

   private:
    ontime::Allocator& inner_;
    std::vector<ontime::State>& states_;
  };
  std::vector<ontime::State> states;
  Recorder recorder(allocator, states);
  ontime::HiddenWorld world(mdp.problem(), 9);
  for (int episode = 0; episode < episodes; ++episode) {
    ontime::run_episode(mdp, recorder, world, ontime::stream_seed(9, static_cast<std::uint64_t>(episode)));
  }
  return states;
}

// dp-rerun's decisions in the states its own `episodes` episodes visit, cycled through.
void time_dp_rerun_decisions(benchmark::State& bench, const ontime::Problem& problem, int episodes) {
  const ontime::Mdp mdp(problem);
  ontime::DpRerunAllocator allocator(mdp);
  const std::vector<ontime::State> states = decision_states(mdp, allocator, episodes);
  std::size_t next = 0;
  for (auto _ : bench) {
    benchmark::DoNotOptimize(allocator.choose(states[next]));
    next = next + 1 == states.size() ? 0 : next + 1;
  }
  bench.counters["states"] = static_cast<double>(states.size());
  bench.SetLabel(problem.name());
}

void BM_DpRerunDecision(benchmark::State& bench) {
  time_dp_rerun_decisions(bench, paper(static_cast<int>(bench.range(0))), 2000);
}
BENCHMARK(BM_DpRerunDecision)->DenseRange(1, 5);

// The same instance with SeSamE's backtracking (SPEC §7) on every action after a skeleton's first:
// a fifth of each planning mass becomes backtrack mass at the same step, blaming the action just
// before. dp-rerun then values skeletons with the extended Eq. (1) (BacktrackingSuccess).
ontime::Problem with_sesame_backtracking(const ontime::Problem& problem) {
  std::vector<ontime::Action> actions(problem.actions().begin(), problem.actions().end());
  for (int a = 0; a < problem.action_count(); ++a) {
    const int parent = problem.parent(a);
    if (parent < 0) continue;
    ontime::Action& action = actions[static_cast<std::size_t>(a)];
    std::vector<double> planning(action.planning.masses().begin(), action.planning.masses().end());
    std::vector<double> backtrack(planning.size(), 0.0);
    for (std::size_t t = 0; t < planning.size(); ++t) {
      backtrack[t] = planning[t] / 5;
      planning[t] -= backtrack[t];
    }
    action.planning = ontime::Distribution::from_pmf(std::move(planning));
    action.backtrack = ontime::Distribution::from_pmf(std::move(backtrack));
    action.culprits = {{problem.action(parent).id, 1.0}};
  }
  return problem.with_actions(std::move(actions));
}

void BM_DpRerunDecisionBacktracking(benchmark::State& bench) {
  time_dp_rerun_decisions(bench, with_sesame_backtracking(paper(static_cast<int>(bench.range(0)))), 2000);
}
BENCHMARK(BM_DpRerunDecisionBacktracking)->DenseRange(1, 5);

// A task planner's many skeletons: `families` groups of skeletons sharing their first two
// actions, each skeleton with three more of its own, D = 200. Planning takes 1-30 steps (with
// some chance of never), execution 0-10.
ontime::Problem wide_problem(int skeletons, int per_family) {
  ontime::SplitMix64 generator(17);
  const auto distribution = [&](int first, int last, double never) {
    std::vector<double> masses(static_cast<std::size_t>(last) + 1, 0.0);
    double total = 0;
    for (int i = 0; i < 3; ++i) {
      const double weight = 0.1 + ontime::uniform01(generator);
      masses[static_cast<std::size_t>(
          first + static_cast<int>(generator() % static_cast<std::uint64_t>(last - first + 1)))] += weight;
      total += weight;
    }
    for (double& mass : masses) mass *= (1.0 - never) / total;
    return ontime::Distribution::from_pmf(std::move(masses));
  };
  std::vector<ontime::Action> actions;
  const auto add_action = [&] {
    std::string id = std::to_string(actions.size());
    id.insert(0, 1, 'a');  // not "a" + ...: GCC 12 warns falsely (-Wrestrict) about that at -O3
    actions.push_back(ontime::Action{std::move(id), distribution(1, 30, 0.1), distribution(0, 10, 0.0)});
    return static_cast<int>(actions.size()) - 1;
  };
  std::vector<std::vector<int>> paths;
  std::vector<int> family;
  for (int k = 0; k < skeletons; ++k) {
    if (k % per_family == 0) family = {add_action(), add_action()};
    std::vector<int> path = family;
    for (int i = 0; i < 3; ++i) path.push_back(add_action());
    paths.push_back(std::move(path));
  }
  return ontime::Problem("wide", 200, 1.0, std::move(actions), std::move(paths));
}

// dp-rerun on 16 and 1,000 skeletons of 5 actions, D = 200, in the states its own episodes
// visit (target: <= 20 us median with 1,000).
void BM_DpRerunDecisionWide(benchmark::State& bench) {
  time_dp_rerun_decisions(bench, wide_problem(static_cast<int>(bench.range(0)), 8), 50);
}
BENCHMARK(BM_DpRerunDecisionWide)->Arg(16)->Arg(1000)->Unit(benchmark::kMicrosecond);

// One step of a session (choose, then report "not yet") with round-robin, plain (Arg 0) or live
// on the steady clock (Arg 1): the difference is the live accounting (target <= 1 us).
void BM_SessionStep(benchmark::State& bench) {
  const bool live = bench.range(0) != 0;
  // Found at the 1,000th step, D = 2,000: 500 steps never end the session.
  std::vector<double> late(1001, 0.0);
  late[1000] = 1.0;
  const ontime::Problem problem(
      "late", 2000, 1.0,
      {ontime::Action{"a", ontime::Distribution::from_pmf(late), ontime::Distribution::from_pmf({1.0})}}, {{0}});
  const ontime::Mdp mdp(problem);
  ontime::RoundRobinAllocator allocator(1);
  const ontime::SteadyClock clock;
  std::uint64_t steps = 0;
  while (bench.KeepRunning()) {
    bench.PauseTiming();
    ontime::Session session = live ? ontime::Session(mdp, allocator, 0, clock) : ontime::Session(mdp, allocator, 0);
    bench.ResumeTiming();
    for (int i = 0; i < 500; ++i) {
      session.choose();
      session.report_not_yet();
    }
    steps += 500;
  }
  bench.SetItemsProcessed(static_cast<std::int64_t>(steps));
  bench.SetLabel(live ? "live" : "plain");
}
BENCHMARK(BM_SessionStep)->Arg(0)->Arg(1);

void BM_DpRerunTables(benchmark::State& bench) {
  const ontime::Problem problem = paper(static_cast<int>(bench.range(0)));
  const ontime::Mdp mdp(problem);
  for (auto _ : bench) {
    ontime::ContiguousSuccessTable table(mdp, ontime::Aggregation::sum);
    benchmark::DoNotOptimize(&table);
  }
  bench.SetLabel(problem.name());
}
BENCHMARK(BM_DpRerunTables)->DenseRange(1, 5)->Unit(benchmark::kMicrosecond);

// dp-rerun's moves when the robot acts while planning (SPEC §10), in the states its own
// `episodes` episodes visit (each drawn from the model's outcomes), cycled through.
void BM_ConcurrentDpRerunDecision(benchmark::State& bench) {
  const ontime::Problem problem = paper(static_cast<int>(bench.range(0)));
  const ontime::ConcurrentMdp mdp(problem);
  ontime::ConcurrentDpRerunAllocator policy(mdp);
  std::vector<ontime::ConcurrentState> states;
  ontime::SplitMix64 generator(9);
  std::vector<std::pair<double, ontime::ConcurrentState>> outcomes;
  for (int episode = 0; episode < 2000; ++episode) {
    ontime::ConcurrentState state = mdp.start();
    while (mdp.any_live(state)) {
      states.push_back(state);
      const ontime::ConcurrentMdp::Move move = policy.choose(state);
      if (move.is_start()) {
        ontime::ConcurrentMdp::StartOutcome started = mdp.start_action(state, move.start);
        if (started.ends) break;
        state = std::move(started.next);
        continue;
      }
      if (ontime::ConcurrentMdp::time(state) >= mdp.deadline()) break;
      outcomes.clear();
      mdp.for_each_step_outcome(state, move.refine, [&](double probability, const ontime::ConcurrentState& next) {
        outcomes.emplace_back(probability, next);
      });
      state = outcomes[ontime::sample_index(
                           outcomes.size(), [&](std::size_t i) { return outcomes[i].first; }, generator)]
                  .second;
    }
  }
  std::size_t next = 0;
  for (auto _ : bench) {
    benchmark::DoNotOptimize(policy.choose(states[next]));
    next = next + 1 == states.size() ? 0 : next + 1;
  }
  bench.counters["states"] = static_cast<double>(states.size());
  bench.SetLabel(problem.name());
}
BENCHMARK(BM_ConcurrentDpRerunDecision)->DenseRange(1, 5);

// The moves of the registry's allocators acting while planning (SPEC §10), each by its commit rule,
// in the states of 500 of their own episodes in hidden sampled worlds (ConcurrentSession), cycled
// through: argument 0 the kind (below), argument 1 the instance.
const std::vector<std::string> kConcurrentKinds = {"dp-rerun", "optimal", "greedy", "round-robin", "thompson"};
void BM_ConcurrentAllocatorMove(benchmark::State& bench) {
  const std::string& kind = kConcurrentKinds[static_cast<std::size_t>(bench.range(0))];
  const ontime::Problem problem = paper(static_cast<int>(bench.range(1))).with_acting(ontime::Acting::concurrent);
  const ontime::ConcurrentMdp mdp(problem);
  const auto allocator = ontime::make_concurrent_allocator_factory(kind, mdp)();
  ontime::HiddenWorld world(problem, 0);
  std::vector<ontime::ConcurrentState> states;
  for (std::uint64_t episode = 0; episode < 500; ++episode) {
    world.begin_episode(episode);
    ontime::ConcurrentSession session(mdp, *allocator, episode);
    while (session.status() == ontime::Status::running) {
      states.push_back(session.state());
      if (!session.choose().is_start() && session.status() == ontime::Status::running) session.carry_out(world);
    }
  }
  allocator->begin_episode(1);
  std::size_t next = 0;
  for (auto _ : bench) {
    benchmark::DoNotOptimize(allocator->choose(states[next]));
    next = next + 1 == states.size() ? 0 : next + 1;
  }
  bench.counters["states"] = static_cast<double>(states.size());
  bench.SetLabel(kind + " " + problem.name());
}
BENCHMARK(BM_ConcurrentAllocatorMove)->ArgsProduct({{0, 1, 2, 3, 4}, {1, 2}});

// Whole episodes acting while planning in hidden sampled worlds: dp-rerun's moves, the world's
// answers and the session's steps (run_concurrent_episode), per episode.
void BM_ConcurrentEpisode(benchmark::State& bench) {
  const ontime::Problem problem = paper(static_cast<int>(bench.range(0))).with_acting(ontime::Acting::concurrent);
  const ontime::ConcurrentMdp mdp(problem);
  const auto allocator = ontime::make_concurrent_allocator_factory("dp-rerun", mdp)();
  ontime::HiddenWorld world(problem, 0);
  std::uint64_t seed = 0;
  for (auto _ : bench) {
    benchmark::DoNotOptimize(ontime::run_concurrent_episode(mdp, *allocator, world, ++seed).status);
  }
  bench.SetLabel(problem.name());
}
BENCHMARK(BM_ConcurrentEpisode)->DenseRange(1, 5);

// The exact optimum of acting while planning (SPEC §10) by the memoised solver of its MDP.
void BM_ConcurrentSolve(benchmark::State& bench) {
  const ontime::Problem problem = paper(static_cast<int>(bench.range(0)));
  const ontime::ConcurrentMdp mdp(problem);
  std::size_t states = 0;
  for (auto _ : bench) {
    ontime::ConcurrentSolver solver(mdp);
    benchmark::DoNotOptimize(solver.solve(mdp.start()));
    states = solver.states();
  }
  bench.counters["states"] = static_cast<double>(states);
  bench.SetLabel(problem.name());
}
BENCHMARK(BM_ConcurrentSolve)->DenseRange(0, 5)->Unit(benchmark::kMicrosecond);

// Navigation acting while planning with its deadline cut to 16 steps (1.48 million states): range(0)
// 0 the memoised solver; 1, 2 the layered solver (concurrent_layered_solver.hpp) on that many
// threads, the same value to the bit. Its counters: the states and, layered, the peak memory and
// scratch.
void BM_ConcurrentNavigation16(benchmark::State& bench) {
  const ontime::Problem navigation =
      ontime::load_problem(std::string(ONTIME_SOURCE_DIR) + "/data/instances/navigation.json");
  std::vector<std::vector<int>> skeletons;
  for (int k = 0; k < navigation.skeleton_count(); ++k) {
    skeletons.emplace_back(navigation.skeleton(k).begin(), navigation.skeleton(k).end());
  }
  const ontime::Problem problem("navigation-16", 16, navigation.step_seconds(),
                                std::vector<ontime::Action>(navigation.actions().begin(), navigation.actions().end()),
                                skeletons);
  const ontime::ConcurrentMdp mdp(problem);
  const auto threads = static_cast<unsigned>(bench.range(0));
  for (auto _ : bench) {
    if (threads == 0) {
      ontime::ConcurrentSolver solver(mdp);
      bench.counters["value"] = solver.solve(mdp.start());
      bench.counters["states"] = static_cast<double>(solver.states());
    } else {
      ontime::LayeredSolveOptions options;
      options.threads = threads;
      const ontime::ConcurrentSolution solution = ontime::solve_concurrent_layered(mdp, options);
      bench.counters["value"] = solution.lower;
      bench.counters["states"] = static_cast<double>(solution.solved);
      bench.counters["peak_MiB"] = static_cast<double>(solution.peak_memory_bytes) / (1 << 20);
      bench.counters["disk_MiB"] = static_cast<double>(solution.peak_disk_bytes) / (1 << 20);
    }
  }
  bench.SetLabel(threads == 0 ? "memoised" : "layered");
}
BENCHMARK(BM_ConcurrentNavigation16)->DenseRange(0, 2)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

void BM_OptimalSolve(benchmark::State& bench) {
  const ontime::Problem problem = paper(static_cast<int>(bench.range(0)));
  const ontime::Mdp mdp(problem);
  std::size_t states = 0;
  for (auto _ : bench) {
    ontime::OptimalSolver solver(mdp);
    benchmark::DoNotOptimize(solver.solve(mdp.start()));
    states = solver.states();
  }
  bench.counters["states"] = static_cast<double>(states);
  bench.SetLabel(problem.name());
}
BENCHMARK(BM_OptimalSolve)->DenseRange(0, 5)->Unit(benchmark::kMicrosecond);

// Exogenous chains (SPEC §9): the same meeting-with-coffee problem with a queue of n states (a
// birth-death chain: one arrival w.p. 0.3, one service w.p. 0.4 per step; waiting in state s
// takes 2s + 1 steps), nothing else varied. The optimum's cost should grow at most
// linearly in n (the BigO fit).
ontime::Problem queue_problem(int states) {
  std::string names;
  std::string rows;
  std::string waits;
  for (int s = 0; s < states; ++s) {
    const std::string name = "\"q" + std::to_string(s) + "\"";
    names += (s > 0 ? ", " : "") + name;
    std::vector<double> row(static_cast<std::size_t>(states), 0.0);
    const double up = s + 1 < states ? 0.3 * (s > 0 ? 0.6 : 1.0) : 0.0;
    const double down = s > 0 ? 0.4 * (s + 1 < states ? 0.7 : 1.0) : 0.0;
    if (s + 1 < states) row[static_cast<std::size_t>(s) + 1] = up;
    if (s > 0) row[static_cast<std::size_t>(s) - 1] = down;
    row[static_cast<std::size_t>(s)] = 1.0 - up - down;
    std::string text;
    for (std::size_t t = 0; t < row.size(); ++t) text += (t > 0 ? ", " : "") + std::to_string(row[t]);
    rows += std::string(s > 0 ? ", " : "") + "[" + text + "]";
    waits += (s > 0 ? ", " : "") + name + ": {\"pmf\": {\"" + std::to_string(2 * s + 1) + "\": 1.0}}";
  }
  return ontime::parse_problem(R"({"deadline": 24, "chains": {"queue": {"states": [)" + names +
                                   R"(], "start": "q0", "transitions": [)" + rows +
                                   R"(]}},
      "actions": {
        "go": {"planning": {"pmf": {"1": 0.3, "2": 0.3, "3": 0.2, "5": 0.1}}, "execution": {"pmf": {"2": 0.5, "3": 0.5}}},
        "wait": {"planning": {"pmf": {"1": 0.6, "2": 0.3}}, "execution": {"chain": "queue", "by_state": {)" +
                                   waits + R"(}}},
        "enter": {"planning": {"pmf": {"2": 0.5, "3": 0.3, "6": 0.1}}, "execution": {"pmf": {"1": 1.0}},
                  "expires": {"after": 22}},
        "walk": {"planning": {"pmf": {"2": 0.3, "4": 0.3, "8": 0.2}}, "execution": {"pmf": {"4": 0.6, "7": 0.4}}}},
      "skeletons": [["go", "wait", "enter"], ["walk"]],
      "rewards": [{"value": 1.0, "per_step": 0.02}, {"value": 0.7, "per_step": 0.01}]})",
                               "queue-" + std::to_string(states));
}

void BM_OptimalSolveChainStates(benchmark::State& bench) {
  const ontime::Problem problem = queue_problem(static_cast<int>(bench.range(0)));
  const ontime::Mdp mdp(problem);
  std::size_t states = 0;
  double value = 0;
  for (auto _ : bench) {
    ontime::OptimalSolver solver(mdp);
    value = solver.solve(mdp.start());
    states = solver.states();
  }
  bench.counters["states"] = static_cast<double>(states);
  bench.counters["optimum"] = value;
  bench.SetComplexityN(bench.range(0));
}
BENCHMARK(BM_OptimalSolveChainStates)
    ->RangeMultiplier(2)
    ->Range(2, 64)
    ->Complexity(benchmark::oN)
    ->Unit(benchmark::kMillisecond);

// The layered solver on the domains (docs/performance.md): the navigation optimum (target
// <= 10 s and <= 1 GiB on 2 cores) and the kitchen's split interval (target: width <= 0.02).
// Real time, all hardware threads, once each (seconds of work).
void time_layered(benchmark::State& bench, const std::string& instance, ontime::SplitMode split) {
  const ontime::Problem problem =
      ontime::load_problem(std::string(ONTIME_SOURCE_DIR) + "/data/instances/" + instance + ".json");
  const ontime::Mdp mdp(problem);
  ontime::LayeredSolution solution;
  for (auto _ : bench) {
    ontime::LayeredSolveOptions options;
    options.split = split;
    solution = ontime::solve_layered(mdp, options);
  }
  bench.counters["states"] = static_cast<double>(solution.states);
  bench.counters["peak_MiB"] = static_cast<double>(solution.peak_memory_bytes) / (1 << 20);
  bench.counters["lower"] = solution.lower;
  bench.counters["upper"] = solution.upper;
  bench.SetLabel(problem.name());
}
void BM_LayeredNavigationOptimum(benchmark::State& bench) {
  time_layered(bench, "navigation", ontime::SplitMode::never);
}
BENCHMARK(BM_LayeredNavigationOptimum)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
void BM_LayeredKitchenSplit(benchmark::State& bench) { time_layered(bench, "manipulation", ontime::SplitMode::always); }
BENCHMARK(BM_LayeredKitchenSplit)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// The branch-and-bound search (solve/search_solver.hpp) on the navigation optimum, one thread:
// against BM_LayeredNavigationOptimum (target: five times faster, the same value).
void BM_SearchNavigationOptimum(benchmark::State& bench) {
  const ontime::Problem problem =
      ontime::load_problem(std::string(ONTIME_SOURCE_DIR) + "/data/instances/navigation.json");
  const ontime::Mdp mdp(problem);
  ontime::SearchSolution solution;
  for (auto _ : bench) solution = ontime::solve_search(mdp);
  bench.counters["states"] = static_cast<double>(solution.states);
  bench.counters["upper_tests"] = static_cast<double>(solution.tested);
  bench.counters["value"] = solution.lower;
  bench.SetLabel(problem.name());
}
BENCHMARK(BM_SearchNavigationOptimum)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// MCTS search throughput from the start state of instance 1, one core (target >= 1e6/s).
// range(1): 0 the paper's backups (mean, random rollouts); 1 bellman backups with the
// clairvoyant bound as leaf value (no rollouts).
void BM_MctsIterations(benchmark::State& bench) {
  const ontime::Problem problem = paper(1);
  const ontime::Mdp mdp(problem);
  ontime::MctsOptions options;
  options.budget = ontime::DecisionBudget::iterations(static_cast<std::uint64_t>(bench.range(0)));
  const bool bellman = bench.range(1) != 0;
  if (bellman) {
    options.backup = ontime::MctsBackup::bellman;
    options.leaf_bounds = std::make_shared<const ontime::ValueBounds>(mdp);
  }
  ontime::MctsAllocator mcts(mdp, options);
  std::uint64_t episode = 0;
  for (auto _ : bench) {
    mcts.begin_episode(++episode);  // a fresh tree every time
    benchmark::DoNotOptimize(mcts.choose(mdp.start()));
  }
  ontime::Statistics statistics;
  mcts.collect_statistics(statistics);
  bench.SetItemsProcessed(static_cast<std::int64_t>(statistics.find("iterations").value_or(0)));
  bench.counters["tree_MiB"] = statistics.find("peak_tree_bytes").value_or(0) / (1 << 20);
  bench.counters["tree_nodes"] = statistics.find("peak_tree_nodes").value_or(0);
  bench.SetLabel(bellman ? "instance 1, root search, bellman, upper leaves, iterations/s"
                         : "instance 1, root search, iterations/s");
}
BENCHMARK(BM_MctsIterations)
    ->Args({10'000, 0})
    ->Args({1'000'000, 0})
    ->Args({10'000, 1})
    ->Args({1'000'000, 1})
    ->Unit(benchmark::kMillisecond);

// PPO training of 10,000 episodes (target <= 60 s on any paper instance).
void BM_PpoTraining(benchmark::State& bench) {
  const ontime::Problem problem = paper(static_cast<int>(bench.range(0)));
  const ontime::Mdp mdp(problem);
  for (auto _ : bench) benchmark::DoNotOptimize(ontime::train_ppo(mdp, 10'000, 1).curve.size());
  bench.SetLabel(problem.name() + ", 10,000 episodes");
}
BENCHMARK(BM_PpoTraining)->DenseRange(1, 5)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

void BM_MonteCarloEpisodes(benchmark::State& bench) {
  const ontime::Problem problem = paper(1);
  const ontime::Mdp mdp(problem);
  const ontime::AllocatorFactory factory = ontime::make_allocator_factory("dp-rerun", mdp);
  ontime::MonteCarloOptions options;
  options.episodes = 10'000;
  options.threads = 1;
  options.time_decisions = bench.range(0) != 0;
  for (auto _ : bench) benchmark::DoNotOptimize(ontime::run_monte_carlo(mdp, factory, options).successes);
  bench.SetItemsProcessed(bench.iterations() * static_cast<std::int64_t>(options.episodes));
  bench.SetLabel(options.time_decisions ? "dp-rerun, instance 1, 1 thread, timed decisions"
                                        : "dp-rerun, instance 1, 1 thread");
}
BENCHMARK(BM_MonteCarloEpisodes)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// What `ontime table instance1..5 --solvers optimal,dp,dp-rerun,round-robin,greedy --exact`
// computes: 5 instances x 5 allocators x 10,000 episodes, plus exact values and optima.
void BM_TableOneWorkload(benchmark::State& bench) {
  std::vector<ontime::Problem> problems;
  for (int i = 1; i <= 5; ++i) problems.push_back(paper(i));
  for (auto _ : bench) {
    for (const ontime::Problem& problem : problems) {
      const ontime::Mdp mdp(problem);
      for (const std::string& name :
           ontime::allocator_registry().names({ontime::Capability::stationary}, {ontime::Capability::needs_policy})) {
        const ontime::AllocatorFactory factory = ontime::make_allocator_factory(name, mdp);
        ontime::MonteCarloOptions options;
        options.episodes = 10'000;
        benchmark::DoNotOptimize(ontime::run_monte_carlo(mdp, factory, options).successes);
        const auto allocator = factory();
        benchmark::DoNotOptimize(ontime::evaluate_exactly(mdp, *allocator).success_probability);
      }
      ontime::OptimalSolver solver(mdp);
      benchmark::DoNotOptimize(solver.solve(mdp.start()));
    }
  }
}
BENCHMARK(BM_TableOneWorkload)->Unit(benchmark::kMillisecond)->UseRealTime();

// An instance whose `actions` object has `keys` members (one used, the others unused).
std::string instance_with_actions(std::int64_t keys) {
  std::string text =
      R"({"deadline": 3, "actions": {"a": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"1": 1.0}}})";
  for (std::int64_t i = 1; i < keys; ++i) {
    text += ", \"u" + std::to_string(i) + R"(": {"planning": {"pmf": {"2": 0.5}}, "execution": {"pmf": {"1": 1.0}}})";
  }
  return text + R"(}, "skeletons": [["a"]]})";
}

// Loading an instance of 10k, 100k and 1M action keys.
void BM_LoadManyActions(benchmark::State& bench) {
  const std::string text = instance_with_actions(bench.range(0));
  for (auto _ : bench) benchmark::DoNotOptimize(ontime::parse_problem(text, "many-actions.json"));
  bench.SetComplexityN(bench.range(0));
  bench.SetBytesProcessed(static_cast<std::int64_t>(bench.iterations()) * static_cast<std::int64_t>(text.size()));
}
BENCHMARK(BM_LoadManyActions)
    ->Arg(10'000)
    ->Arg(100'000)
    ->Arg(1'000'000)
    ->Complexity(benchmark::oN)
    ->Unit(benchmark::kMillisecond);

// Loading one PMF of 10k and 100k keys (steps are capped at Distribution::kMaxStep).
void BM_LoadLongPmf(benchmark::State& bench) {
  std::string pmf;
  for (std::int64_t step = 1; step <= bench.range(0); ++step) {
    pmf += (step == 1 ? "\"" : ", \"") + std::to_string(step) + "\": 1e-6";
  }
  const std::string text = R"({"deadline": 3, "actions": {"a": {"planning": {"pmf": {)" + pmf +
                           R"(}}, "execution": {"pmf": {"1": 1.0}}}}, "skeletons": [["a"]]})";
  for (auto _ : bench) benchmark::DoNotOptimize(ontime::parse_problem(text, "long-pmf.json"));
  bench.SetComplexityN(bench.range(0));
}
BENCHMARK(BM_LoadLongPmf)->Arg(10'000)->Arg(100'000)->Complexity(benchmark::oN)->Unit(benchmark::kMillisecond);

// Reading a planner log of 10k, 100k and 1M lines.
void BM_LoadPlannerLog(benchmark::State& bench) {
  std::string text;
  for (std::int64_t line = 0; line < bench.range(0); ++line) {
    text += R"({"action": "a)" + std::to_string(line % 100) +
            R"(", "planning_seconds": 1.5, "found": false})"
            "\n";
  }
  for (auto _ : bench) benchmark::DoNotOptimize(ontime::parse_planner_log(text, "log.jsonl"));
  bench.SetComplexityN(bench.range(0));
}
BENCHMARK(BM_LoadPlannerLog)
    ->Arg(10'000)
    ->Arg(100'000)
    ->Arg(1'000'000)
    ->Complexity(benchmark::oN)
    ->Unit(benchmark::kMillisecond);

}  // namespace

// One online update of an action's planning distribution and the posterior to replan with, at the
// 30-room building's horizon of 45 steps (issue target: 10 us): an attempt cut off after 20 steps.
void BM_PosteriorUpdate(benchmark::State& bench) {
  std::vector<double> masses(46, 0.0);
  for (std::size_t t = 1; t <= 45; ++t) masses[t] = 0.8 / 45;
  ontime::PlanningPosterior posterior(ontime::Distribution::from_pmf(masses), 45, 5.0);
  for (auto _ : bench) {
    posterior.observe_cut_off(20);
    benchmark::DoNotOptimize(posterior.mean());
  }
}
BENCHMARK(BM_PosteriorUpdate)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
