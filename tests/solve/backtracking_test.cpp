// Backtracking (SPEC §7): the exact solver and exact evaluation against an independent
// implementation written for the test (tests/support/backtracking_reference.hpp: its own state
// and transitions, and the hidden worlds enumerated attempt by attempt), the simulator against
// the exact values, instances whose backtrack probabilities are all zero against today's model
// bit for bit, and the instance format's rules with their places.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/solve/backtracking_success.hpp"
#include "ontime/solve/layered_solver.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/solve/search_solver.hpp"
#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "support/backtracking_reference.hpp"
#include "support/exact_solver_checks.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

using testing::with_backtracking;

// Stationary rules written twice: on the library's state (an allocator) and on the reference's.
class LowestWithWork final : public Allocator {
 public:
  explicit LowestWithWork(const Mdp& mdp) : mdp_(&mdp) {}
  std::string_view name() const noexcept override { return "lowest-with-work"; }
  int choose(const State& state) override {
    for (int k = 0; k < mdp_->skeleton_count(); ++k) {
      if (mdp_->next_action(state, k) >= 0) return k;
    }
    return 0;
  }

 private:
  const Mdp* mdp_;
};

int lowest_with_work(const testing::BacktrackingReference& reference,
                     const testing::BacktrackingReference::Node& node) {
  for (int k = 0; k < reference.problem().skeleton_count(); ++k) {
    if (reference.next_action(node, k) >= 0) return k;
  }
  return 0;
}

// Skeleton CT mod K when it has work left, else the lowest that has.
class Rotating final : public Allocator {
 public:
  explicit Rotating(const Mdp& mdp) : mdp_(&mdp) {}
  std::string_view name() const noexcept override { return "rotating"; }
  int choose(const State& state) override {
    const int turn = state.time % mdp_->skeleton_count();
    if (mdp_->next_action(state, turn) >= 0) return turn;
    return LowestWithWork(*mdp_).choose(state);
  }

 private:
  const Mdp* mdp_;
};

int rotating(const testing::BacktrackingReference& reference, const testing::BacktrackingReference::Node& node) {
  const int turn = node.time % reference.problem().skeleton_count();
  return reference.next_action(node, turn) >= 0 ? turn : lowest_with_work(reference, node);
}

TEST(Backtracking, ExactValuesEqualAnIndependentImplementation) {
  int backtracking = 0;
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Problem problem = with_backtracking(testing::random_instance(seed, 3, 3, 6), seed + 1000);
    backtracking += problem.has_backtracking() ? 1 : 0;
    const Mdp mdp(problem);
    testing::BacktrackingReference reference(problem);
    OptimalSolver solver(mdp);
    const double optimum = solver.solve(mdp.start());
    EXPECT_NEAR(optimum, reference.optimum(), 1e-12);
    LowestWithWork lowest(mdp);
    const double lowest_value = evaluate_exactly(mdp, lowest).success_probability;
    EXPECT_NEAR(lowest_value, reference.value_of(lowest_with_work), 1e-12);
    Rotating rotation(mdp);
    EXPECT_NEAR(evaluate_exactly(mdp, rotation).success_probability, reference.value_of(rotating), 1e-12);
    EXPECT_LE(lowest_value, optimum + 1e-12);
  }
  EXPECT_GE(backtracking, 40);  // most instances do backtrack
}

// Skeleton k alone, as a problem of its own (its actions and their culprits, all on its path).
Problem alone(const Problem& problem, int k) {
  std::vector<Action> actions;
  std::vector<int> path;
  for (const int action : problem.skeleton(k)) {
    path.push_back(static_cast<int>(actions.size()));
    actions.push_back(problem.action(action));
  }
  return {problem.name(), problem.deadline(), problem.step_seconds(), std::move(actions), {path}};
}

// Eq. (1)'s extension (dp, dp-rerun) on one skeleton alone is the success probability of
// refining it, which the exact solver computes: from the start and from every state on the way.
TEST(Backtracking, TheContiguousSuccessOfOneSkeletonIsItsExactValue) {
  int checked = 0;
  for (std::uint64_t seed = 1; seed <= 100; ++seed) {
    const Problem problem = with_backtracking(testing::random_instance(seed, 3, 3, 7), seed + 2000);
    for (int k = 0; k < problem.skeleton_count(); ++k) {
      const Problem single = alone(problem, k);
      if (!single.has_backtracking()) continue;
      SCOPED_TRACE("seed " + std::to_string(seed) + " skeleton " + std::to_string(k));
      const Mdp mdp(single);
      OptimalSolver solver(mdp);
      BacktrackingSuccess success(mdp, Aggregation::self);
      HiddenWorld world(single, seed);
      State state = mdp.start();
      for (Status status = Status::running; status == Status::running;) {
        EXPECT_NEAR(success.success_probability(state, 0), solver.solve(state), 1e-12);
        ++checked;
        status = mdp.apply(state, 0, world.step(mdp.next_action(state, 0), state.spent[0]));
      }
    }
  }
  EXPECT_GT(checked, 100);
}

// dp and dp-rerun plan with it on random backtracking instances: stationary, so exactly
// evaluable, and never above the optimum.
TEST(Backtracking, DpAndDpRerunDecideWithTheExtendedEquation) {
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const Problem problem = with_backtracking(testing::random_instance(seed, 3, 3, 7), seed + 3000);
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    const double optimum = solver.solve(mdp.start());
    const auto dp = make_allocator_factory("dp", mdp)();
    const auto rerun = make_allocator_factory("dp-rerun", mdp)();
    const double dp_value = evaluate_exactly(mdp, *dp).success_probability;
    const double rerun_value = evaluate_exactly(mdp, *rerun).success_probability;
    EXPECT_LE(dp_value, optimum + 1e-12);
    EXPECT_LE(rerun_value, optimum + 1e-12);
  }
}

// Every allocator of the registry runs under backtracking: the stationary ones' exact values stay
// below the optimum and their simulated success rates agree with them, the randomised ones'
// rates stay below the optimum (within sampling error). ppo, which needs a trained policy, is
// tested in tests/learn/ppo_test.cpp (Ppo.DecidesUnderBacktracking).
TEST(Backtracking, EveryAllocatorDecidesUnderIt) {
  const AllocatorRegistry& registry = allocator_registry();
  int instances = 0;
  for (std::uint64_t seed = 1; instances < 4; ++seed) {
    const Problem problem = with_backtracking(testing::random_instance(seed, 3, 3, 7), seed + 4000);
    if (!problem.has_backtracking()) continue;
    ++instances;
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    const double optimum = solver.solve(mdp.start());
    for (const std::string& name : registry.names({}, {Capability::needs_policy})) {
      SCOPED_TRACE("seed " + std::to_string(seed) + " " + name);
      const ParameterValues values = name == "mcts" ? ParameterValues{{"iterations", "200"}} : ParameterValues{};
      const AllocatorFactory factory = make_allocator_factory(name, mdp, values);
      MonteCarloOptions options;
      options.episodes = name == "mcts" ? 1'000 : 4'000;
      options.seed = seed;
      options.threads = 1;
      const double rate = run_monte_carlo(mdp, factory, options).success_rate;
      const double error = std::sqrt(std::max(optimum * (1 - optimum), 1e-4) / static_cast<double>(options.episodes));
      EXPECT_LE(rate, optimum + 4 * error);
      if (registry.find(name).capabilities.has(Capability::stationary)) {
        const double exact = evaluate_exactly(mdp, *factory()).success_probability;
        EXPECT_LE(exact, optimum + 1e-12);
        EXPECT_NEAR(rate, exact,
                    4 * std::sqrt(std::max(exact * (1 - exact), 1e-4) / static_cast<double>(options.episodes)));
      }
    }
  }
}

// The simulator's hidden worlds (each attempt drawn from its own stream) give the exact value's
// success rate.
TEST(Backtracking, SimulatedEpisodesAgreeWithTheExactValue) {
  int inside = 0, cases = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const Problem problem = with_backtracking(testing::random_instance(seed, 3, 3, 6), seed + 1000);
    if (!problem.has_backtracking()) continue;
    const Mdp mdp(problem);
    LowestWithWork lowest(mdp);
    const double exact = evaluate_exactly(mdp, lowest).success_probability;
    MonteCarloOptions options;
    options.episodes = 20'000;
    options.seed = seed;
    options.threads = 1;
    const MonteCarloResult sampled = run_monte_carlo(
        mdp, [&mdp] { return std::make_unique<LowestWithWork>(mdp); }, options);
    const double error = std::sqrt(std::max(exact * (1 - exact), 1e-6) / 20'000.0);
    ++cases;
    inside += std::abs(sampled.success_rate - exact) <= 1.96 * error ? 1 : 0;
  }
  // At 95% each, at most a few outside (a binomial(cases, 0.05) above 4 has probability < 2%).
  EXPECT_GE(inside, cases - 4) << inside << " of " << cases;
}

// Every backtrack probability zero: the model is SPEC §2's, the same values to the last bit.
TEST(Backtracking, ZeroBacktrackProbabilitiesGiveTodaysValuesBitForBit) {
  for (const char* name : {"figure1", "instance1", "instance2", "instance3", "instance4", "instance5"}) {
    SCOPED_TRACE(name);
    const Problem plain = testing::paper_instance(name);
    std::vector<Action> actions(plain.actions().begin(), plain.actions().end());
    for (Action& action : actions) action.backtrack = Distribution::from_pmf({0.0, 0.0});
    const Problem zero = plain.with_actions(std::move(actions));
    EXPECT_FALSE(zero.has_backtracking());
    const Mdp plain_mdp(plain), zero_mdp(zero);
    OptimalSolver plain_solver(plain_mdp), zero_solver(zero_mdp);
    EXPECT_EQ(plain_solver.solve(plain_mdp.start()), zero_solver.solve(zero_mdp.start()));
    for (const char* solver : {"dp-rerun", "greedy"}) {
      const auto plain_allocator = make_allocator_factory(solver, plain_mdp)();
      const auto zero_allocator = make_allocator_factory(solver, zero_mdp)();
      EXPECT_EQ(evaluate_exactly(plain_mdp, *plain_allocator).success_probability,
                evaluate_exactly(zero_mdp, *zero_allocator).success_probability);
    }
  }
  // The navigation instance (collected from the real planner): the allocators' exact values (its
  // optimum is the layered solver's, which refuses nothing here: the zero problem has no
  // backtracking).
  const Problem plain = load_problem(testing::source_path("data/instances/navigation.json"));
  std::vector<Action> actions(plain.actions().begin(), plain.actions().end());
  for (Action& action : actions) action.backtrack = Distribution::from_pmf({0.0, 0.0});
  const Problem zero = plain.with_actions(std::move(actions));
  ASSERT_FALSE(zero.has_backtracking());
  const Mdp plain_mdp(plain), zero_mdp(zero);
  for (const char* solver : {"dp-rerun", "dp", "greedy"}) {
    SCOPED_TRACE(std::string("navigation ") + solver);
    const auto plain_allocator = make_allocator_factory(solver, plain_mdp)();
    const auto zero_allocator = make_allocator_factory(solver, zero_mdp)();
    EXPECT_EQ(evaluate_exactly(plain_mdp, *plain_allocator).success_probability,
              evaluate_exactly(zero_mdp, *zero_allocator).success_probability);
  }
}

// A backtrack discards the culprit's motion and everything after it, for every skeleton through
// it, and restores the execution recorded before it.
TEST(Backtracking, ABacktrackRestoresTheStateBeforeTheCulprit) {
  const Distribution now = Distribution::from_pmf({0.0, 1.0});
  const Distribution two = Distribution::from_pmf({0.0, 0.0, 1.0});
  std::vector<Action> actions{{"a", now, two}, {"b", now, two}, {"c", Distribution::from_pmf({0.0, 0.5}), now}};
  actions[2].backtrack = Distribution::from_pmf({0.0, 0.5});
  actions[2].culprits = {{"b", 1.0}};
  const Problem problem("chain", 20, 1.0, std::move(actions), {{0, 1, 2}, {0, 1}});
  ASSERT_TRUE(problem.has_backtracking());
  EXPECT_EQ(problem.culprit_slot(1), 0);
  const Mdp mdp(problem);
  State state = mdp.start();
  EXPECT_EQ(mdp.apply(state, 0, Observation::found(2)), Status::running);  // a: ET 2
  EXPECT_EQ(mdp.apply(state, 0, Observation::found(2)), Status::success);  // b: skeleton 1 done at 2 + 4
  state = mdp.start();
  mdp.apply(state, 0, Observation::found(2));
  State before_b = state;
  mdp.apply(state, 0, Observation::found(3));
  EXPECT_EQ(state.restore[0], 2);  // B_b: the execution before b
  EXPECT_EQ(state.refined[0], 2);
  EXPECT_EQ(state.execution[0], 5);
  EXPECT_EQ(mdp.apply(state, 0, Observation::backtracked(1)), Status::running);
  EXPECT_EQ(state.time, 3);
  EXPECT_EQ(state.refined[0], 1);
  EXPECT_EQ(state.refined[1], 1);
  EXPECT_EQ(state.execution[0], 2);
  EXPECT_EQ(state.execution[1], 2);
  EXPECT_EQ(state.spent[0], 0);
  EXPECT_EQ(state.restore[0], 0);
  before_b.time = 3;
  EXPECT_EQ(state, before_b);
  // The outcomes of a step on c: found, backtrack to b, nothing else (its hazards end the attempt).
  State at_c = before_b;
  mdp.apply(at_c, 0, Observation::found(1));
  double total = 0;
  int backtracks = 0;
  mdp.for_each_observation(at_c, 0, [&](double probability, const Observation& observation) {
    total += probability;
    backtracks += observation.is_backtrack() ? 1 : 0;
    if (observation.is_backtrack()) {
      EXPECT_EQ(observation.culprit, 1);
      EXPECT_DOUBLE_EQ(probability, 0.5);
    }
  });
  EXPECT_DOUBLE_EQ(total, 1.0);
  EXPECT_EQ(backtracks, 1);
  // A backtrack blaming an action that is not a culprit of the step's action is refused.
  State copy = at_c;
  EXPECT_THROW(mdp.apply(copy, 0, Observation::backtracked(0)), UsageError);
  EXPECT_EQ(copy, at_c);
}

Problem parse(const std::string& actions, const std::string& skeletons = R"([["a", "b"], ["a", "c"]])") {
  return parse_problem(R"({"deadline": 9, "actions": {)" + actions + R"(}, "skeletons": )" + skeletons + "}",
                       "bt.json");
}

std::string error_of(const std::string& actions, const std::string& skeletons = R"([["a", "b"], ["a", "c"]])") {
  try {
    parse(actions, skeletons);
  } catch (const InputError& error) {
    return error.what();
  }
  return "no error";
}

TEST(Backtracking, TheFormatsRulesNameThePlace) {
  const std::string plain_a = R"("a": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"1": 1}}})";
  const std::string plain_c = R"("c": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"1": 1}}})";
  const auto b_with = [](const std::string& extra) {
    return R"("b": {"planning": {"pmf": {"1": 0.5}}, "execution": {"pmf": {"1": 1}})" + extra + "}";
  };
  // A good one reads back the same from its JSON.
  const Problem good =
      parse(plain_a + "," + b_with(R"(, "backtrack": {"pmf": {"2": 0.25}}, "culprits": {"a": 1})") + "," + plain_c);
  EXPECT_TRUE(good.has_backtracking());
  const Problem again = parse_problem(problem_to_json(good), "again.json");
  EXPECT_EQ(again.action(1).backtrack, good.action(1).backtrack);
  ASSERT_EQ(again.culprits(1).size(), 1U);
  EXPECT_EQ(again.culprits(1)[0].action, 0);

  const auto expect = [&](const std::string& b, const std::string& message) {
    const std::string got = error_of(plain_a + "," + b + "," + plain_c);
    EXPECT_NE(got.find(message), std::string::npos) << got;
  };
  expect(b_with(R"(, "backtrack": {"pmf": {"2": 0.25}}, "culprits": {"c": 1})"),
         "actions.b.culprits.c: the culprit is not before the action on its skeletons' path");
  expect(b_with(R"(, "backtrack": {"pmf": {"2": 0.25}}, "culprits": {"b": 1})"),
         "actions.b.culprits.b: an action cannot blame itself");
  expect(b_with(R"(, "backtrack": {"pmf": {"2": 0.25}}, "culprits": {"z": 1})"),
         "actions.b.culprits.z: no such action");
  expect(b_with(R"(, "backtrack": {"pmf": {"2": 0.25}}, "culprits": {"a": 0.5})"),
         "actions.b: the culprits' probabilities sum to 0.500000, not 1");
  expect(b_with(R"(, "backtrack": {"pmf": {"2": 0.25}}, "culprits": {"a": 1.5})"),
         "actions.b.culprits.a: a probability must be within [0, 1]");
  expect(b_with(R"(, "backtrack": {"pmf": {"2": 0.75}}, "culprits": {"a": 1})"),
         "actions.b: planning and backtrack probabilities sum above 1");
  expect(b_with(R"(, "backtrack": {"pmf": {"0": 0.25}}, "culprits": {"a": 1})"),
         "actions.b.backtrack.pmf.\"0\": backtrack steps start at 1");
  expect(b_with(R"(, "backtrack": {"pmf": {"2": 0.25}})"), "actions.b: an action that backtracks needs culprits");
  expect(b_with(R"(, "culprits": {"a": 1})"), "actions.b.culprits.a: culprits without a backtrack distribution");
  expect(b_with(R"(, "backtrack": {"pmf": {"2": -0.1}}, "culprits": {"a": 1})"), "a probability must be within [0, 1]");
  // A culprit after the failing action: "a" blaming "b" below it.
  const std::string got = error_of(
      R"("a": {"planning": {"pmf": {"1": 0.5}}, "execution": {"pmf": {"1": 1}}, "backtrack": {"pmf": {"1": 0.5}}, "culprits": {"b": 1}},)" +
      b_with("") + "," + plain_c);
  EXPECT_NE(got.find("actions.a.culprits.b: the culprit comes after the failing action"), std::string::npos) << got;
}

// The exact solver takes only as many blamed actions as its keys hold; the layered solver and the
// value bounds refuse backtracking for now.
// The layered solver walks the same outcomes in the same order as the memoised one, layer by
// layer: the same value to the bit, the same first choice, the same states, on any thread count;
// the policy it keeps holds the restore values (its states solve to its values).
TEST(Backtracking, TheLayeredSolverEqualsTheMemoisedOneBitForBit) {
  int backtracking = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Problem problem = with_backtracking(testing::random_instance(seed, 3, 3, 6), seed + 1000);
    if (!problem.has_backtracking()) continue;
    ++backtracking;
    testing::expect_layered_equals_memoised(Mdp(problem));
  }
  EXPECT_GE(backtracking, 25);
}

// The search takes the memoised solver's keys and outcomes, and the bounds hold under
// backtracking: the same value to the bit and the same first choice, after trials too.
TEST(Backtracking, TheSearchEqualsTheMemoisedSolverBitForBit) {
  int backtracking = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Problem problem = with_backtracking(testing::random_instance(seed, 3, 3, 6), seed + 1000);
    if (!problem.has_backtracking()) continue;
    ++backtracking;
    testing::expect_search_equals_memoised(Mdp(problem));
  }
  EXPECT_GE(backtracking, 25);
}

TEST(Backtracking, TheLayeredSolverEqualsTheMemoisedOneOnTheExampleAndTheKitchen) {
  for (const char* path : {"data/instances/backtracking/grasp-and-place.json", "data/instances/kitchen-grasps.json"}) {
    SCOPED_TRACE(path);
    const Problem problem = load_problem(testing::source_path(path));
    ASSERT_TRUE(problem.has_backtracking());
    const Mdp mdp(problem);
    OptimalSolver solver(mdp);
    const double optimum = solver.solve(mdp.start());
    const LayeredSolution layered = solve_layered(mdp, LayeredSolveOptions{});
    ASSERT_TRUE(layered.exact);
    EXPECT_EQ(layered.lower, optimum);
    EXPECT_EQ(layered.first_choice, solver.best_choice(mdp.start()).value_or(-1));
    EXPECT_EQ(layered.states, solver.states());
  }
}

// The bounds under backtracking (a give-up ends the commit bound in failure and the relaxation in
// success) hold the optimum in every state random episodes visit; returns the states checked, and
// counts in `informative` those where the interval is narrower than a half and its top below 1.
int check_bounds_along_episodes(const Mdp& mdp, int episodes, std::uint64_t seed, int& informative) {
  OptimalSolver solver(mdp);
  const ValueBounds bounds(mdp);
  SplitMix64 generator(seed);
  int states = 0;
  for (int episode = 0; episode < episodes; ++episode) {
    State state = mdp.start();
    for (Status status = Status::running; status == Status::running;) {
      const double value = solver.solve(state);
      const double lower = bounds.lower(state), upper = bounds.upper(state);
      EXPECT_LE(lower, value + 1e-12);
      EXPECT_GE(upper, value - 1e-12);
      const int committed = bounds.lower_choice(state);
      if (committed >= 0) {
        EXPECT_EQ(bounds.commit(state, committed), lower);
      }
      ++states;
      informative += upper < 1.0 && upper - lower < 0.5 ? 1 : 0;
      const ChoiceList choices = mdp.useful_choices(state);
      if (choices.empty()) break;
      const int choice = choices[generator() % choices.size()];
      status = mdp.apply(state, choice, mdp.sample_observation(state, choice, generator));
    }
  }
  return states;
}

// ... and the layered solver cut by a cap gives an interval that holds the optimum.
TEST(Backtracking, TheBoundsHoldTheOptimumInEveryStateVisited) {
  int states = 0, informative = 0, cut_checked = 0;
  for (std::uint64_t seed = 1; seed <= 80; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Problem problem = with_backtracking(testing::random_instance(seed, 4, 4, 16), seed + 1000);
    if (!problem.has_backtracking()) continue;
    const Mdp mdp(problem);
    states += check_bounds_along_episodes(mdp, 60, seed, informative);
    OptimalSolver solver(mdp);
    const double optimum = solver.solve(mdp.start());
    if (solver.states() < 30) continue;  // too few layers to cut
    ++cut_checked;
    LayeredSolveOptions capped;
    capped.max_states = solver.states() / 3;
    const LayeredSolution cut = solve_layered(mdp, capped);
    EXPECT_FALSE(cut.exact);
    EXPECT_GE(cut.frontier_layer, 0);
    EXPECT_LE(cut.lower, optimum + 1e-12);
    EXPECT_GE(cut.upper, optimum - 1e-12);
  }
  EXPECT_GE(cut_checked, 10);
  EXPECT_GE(states, 1000);
  EXPECT_GE(informative, states / 4);  // the bounds say something in many of them
  // Where backtracking is what makes success possible: the kitchen's direct place gives up on
  // every grasp, its regrasp's last place on four in five.
  for (const char* path : {"data/instances/backtracking/grasp-and-place.json", "data/instances/kitchen-grasps.json"}) {
    SCOPED_TRACE(path);
    const Problem problem = load_problem(testing::source_path(path));
    const Mdp mdp(problem);
    int real_informative = 0;
    EXPECT_GE(check_bounds_along_episodes(mdp, 100, 7, real_informative), 100);
  }
}

TEST(Backtracking, TheLayeredSolverRefusesAToleranceOrASplit) {
  std::uint64_t seed = 1;
  while (!with_backtracking(testing::random_instance(seed, 3, 3, 6), seed + 1000).has_backtracking()) ++seed;
  const Problem problem = with_backtracking(testing::random_instance(seed, 3, 3, 6), seed + 1000);
  const Mdp mdp(problem);
  LayeredSolveOptions tolerance;
  tolerance.tolerance = 0.01;
  EXPECT_THROW(solve_layered(mdp, tolerance), UsageError);
  LayeredSolveOptions split;
  split.split = SplitMode::always;
  EXPECT_THROW(solve_layered(mdp, split), UsageError);
  LayeredSolveOptions fallback;  // a fallback split does not happen: the whole tree, exactly
  fallback.split = SplitMode::fallback;
  const LayeredSolution whole = solve_layered(mdp, fallback);
  EXPECT_TRUE(whole.exact);
  EXPECT_TRUE(whole.split_kept.empty());
}

}  // namespace
}  // namespace ontime
