// The baselines that model planners without a model of their motion planner, taking skeletons
// in the order they were found: `first-found` (PDDLStream's focused habit, a budget per attempt
// that doubles) and `found-order-round-robin` (in turn among the skeletons not known dead).

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/first_found.hpp"
#include "ontime/allocators/found_order_round_robin.hpp"
#include "ontime/allocators/known_dead.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"
#include "support/reference_solver.hpp"

namespace ontime {
namespace {

constexpr Steps kDeadline = 40;

// `count` skeletons of two actions each, none shared. Every action plans in any of 1 .. D steps
// (1/64 each, else never) and executes in 1, so that the model rules no skeleton out until the
// deadline nears and the states below are running states.
Problem separate_skeletons(int count) {
  std::vector<double> planning(kDeadline + 1, 1.0 / 64);
  planning[0] = 0;
  std::vector<Action> actions;
  std::vector<std::vector<int>> skeletons;
  for (int k = 0; k < count; ++k) {
    const int first = static_cast<int>(actions.size());
    for (const char* part : {"a", "b"}) {
      std::string id = std::to_string(k);
      id += part;
      actions.push_back(Action{std::move(id), Distribution::from_pmf(planning), Distribution::from_pmf({0, 1.0})});
    }
    skeletons.push_back({first, first + 1});
  }
  return Problem("separate-" + std::to_string(count), kDeadline, 1.0, std::move(actions), std::move(skeletons));
}

// Skeleton k made dead by observation: its refined actions execute too slowly (the MDP stores
// any such time as D + 1).
void kill(State& state, int k) {
  state.refined[static_cast<std::size_t>(k)] = 1;
  state.execution[static_cast<std::size_t>(k)] = kDeadline + 1;
}

void set_spent(State& state, std::initializer_list<int> spent) {
  std::size_t k = 0;
  for (const int value : spent) state.spent[k++] = static_cast<std::uint16_t>(value);
}

TEST(KnownDead, OnlyWhatIsObservedRulesASkeletonOut) {
  const Problem problem = separate_skeletons(2);
  const Mdp mdp(problem);
  State state = mdp.start();
  EXPECT_FALSE(known_dead(mdp, state, 0));
  // One action refined, executing in 4: at CT = 35 the next motion can be found at 36 and
  // executed by 40 = D; at CT = 36 it cannot.
  state.refined[0] = 1;
  state.execution[0] = 4;
  state.time = 35;
  EXPECT_FALSE(known_dead(mdp, state, 0));
  state.time = 36;
  EXPECT_TRUE(known_dead(mdp, state, 0));
  EXPECT_FALSE(mdp.can_succeed(state, 0));
  // Too slow or never executed (saturated at D + 1), whatever the time.
  State slow = mdp.start();
  kill(slow, 1);
  EXPECT_TRUE(known_dead(mdp, slow, 1));
  // Nothing left to refine.
  State done = mdp.start();
  done.refined[1] = 2;
  EXPECT_TRUE(known_dead(mdp, done, 1));
  EXPECT_FALSE(known_dead(mdp, done, 0));
}

TEST(FirstFound, StaysOnTheFirstSkeletonUntilItsBudgetEndsThenTakesTheNextInFoundOrder) {
  const Problem problem = separate_skeletons(4);
  const Mdp mdp(problem);
  FirstFoundAllocator first_found(mdp, 4);
  State state = mdp.start();
  for (const int spent : {0, 1, 2, 3}) {
    set_spent(state, {spent, 0, 0, 0});
    EXPECT_EQ(first_found.choose(state), 0) << spent;
  }
  set_spent(state, {4, 0, 0, 0});
  EXPECT_EQ(first_found.choose(state), 1);
  set_spent(state, {4, 3, 0, 0});
  EXPECT_EQ(first_found.choose(state), 1);
  set_spent(state, {4, 4, 0, 0});
  EXPECT_EQ(first_found.choose(state), 2);
  // A dead skeleton is skipped.
  kill(state, 2);
  EXPECT_EQ(first_found.choose(state), 3);
  // Every live skeleton abandoned at 4: the budget doubles to 8, from the first skeleton again.
  set_spent(state, {4, 4, 0, 4});
  EXPECT_EQ(first_found.choose(state), 0);
  set_spent(state, {7, 4, 0, 4});
  EXPECT_EQ(first_found.choose(state), 0);
  set_spent(state, {8, 4, 0, 4});
  EXPECT_EQ(first_found.choose(state), 1);
  set_spent(state, {8, 8, 0, 5});
  EXPECT_EQ(first_found.choose(state), 3);
  // Abandoned at 8 too: budget 16. The dead skeleton's spent steps do not count.
  set_spent(state, {8, 9, 0, 8});
  EXPECT_EQ(first_found.choose(state), 0);
  set_spent(state, {16, 9, 0, 8});
  EXPECT_EQ(first_found.choose(state), 1);
  // A skeleton whose action was refined starts its next action at 0 steps: under the first
  // budget again, it comes before the skeletons of the doubled rounds.
  state.refined[3] = 1;
  state.execution[3] = 1;
  set_spent(state, {16, 9, 0, 0});
  EXPECT_EQ(first_found.choose(state), 3);
  // Every skeleton dead: skeleton 0.
  for (int k = 0; k < 4; ++k) kill(state, k);
  EXPECT_EQ(first_found.choose(state), 0);
}

TEST(FirstFound, AnEpisodeStepByStep) {
  const Problem problem = separate_skeletons(4);
  const Mdp mdp(problem);
  FirstFoundAllocator first_found(mdp, 4);
  // No motion is found: four steps on each skeleton in found order, then eight (budget 8:
  // four more each), then budget 16 from skeleton 0.
  State state = mdp.start();
  std::string choices;
  for (int step = 0; step < 34; ++step) {
    const int choice = first_found.choose(state);
    choices += std::to_string(choice);
    ASSERT_EQ(mdp.apply(state, choice, Observation::not_yet()), Status::running) << step;
  }
  EXPECT_EQ(choices, "0000111122223333000011112222333300");
  // A motion found on the third step: skeleton 0's second action gets its own four steps.
  state = mdp.start();
  choices.clear();
  for (int step = 0; step < 9; ++step) {
    const int choice = first_found.choose(state);
    choices += std::to_string(choice);
    mdp.apply(state, choice, step == 2 ? Observation::found(1) : Observation::not_yet());
  }
  EXPECT_EQ(choices, "000000011");
}

TEST(FirstFound, TheBudgetIsAParameter) {
  const Problem problem = separate_skeletons(3);
  const Mdp mdp(problem);
  State state = mdp.start();
  set_spent(state, {2, 0, 0});
  EXPECT_EQ(make_allocator_factory("first-found", mdp)()->choose(state), 0);  // default 4
  const auto two = make_allocator_factory("first-found", mdp, {{"budget", "2"}})();
  EXPECT_EQ(two->choose(state), 1);
  const auto one = make_allocator_factory("first-found", mdp, {{"budget", "1"}})();
  set_spent(state, {1, 1, 1});
  EXPECT_EQ(one->choose(state), 0);  // all abandoned at 1: budget 2
  set_spent(state, {2, 1, 1});
  EXPECT_EQ(one->choose(state), 1);
  EXPECT_THROW(make_allocator_factory("first-found", mdp, {{"budget", "0"}}), UsageError);
  EXPECT_THROW(make_allocator_factory("first-found", mdp, {{"budget", "1.5"}}), UsageError);
}

TEST(FoundOrderRoundRobin, TurnsToTheLiveSkeletonsOnlyInFoundOrder) {
  const Problem problem = separate_skeletons(4);
  const Mdp mdp(problem);
  FoundOrderRoundRobinAllocator round_robin(mdp);
  State state = mdp.start();
  std::string choices;
  for (std::uint16_t time = 0; time < 8; ++time) {
    state.time = time;
    choices += std::to_string(round_robin.choose(state));
  }
  EXPECT_EQ(choices, "01230123");
  kill(state, 1);
  choices.clear();
  for (std::uint16_t time = 0; time < 6; ++time) {
    state.time = time;
    choices += std::to_string(round_robin.choose(state));
  }
  EXPECT_EQ(choices, "023023");
  // Skeleton 2 fully refined (nothing left to refine) and 0 too slow: 3 alone.
  state.refined[2] = 2;
  kill(state, 0);
  state.time = 7;
  EXPECT_EQ(round_robin.choose(state), 3);
  kill(state, 3);
  EXPECT_EQ(round_robin.choose(state), 0);  // all dead
}

TEST(FoundOrderRoundRobin, ItIsTheTimeNotTheHistoryThatPicksTheTurn) {
  // The same live set at the same time gives the same choice, whatever was spent where.
  const Problem problem = separate_skeletons(3);
  const Mdp mdp(problem);
  FoundOrderRoundRobinAllocator round_robin(mdp);
  State state = mdp.start();
  state.time = 10;
  set_spent(state, {0, 5, 5});
  EXPECT_EQ(round_robin.choose(state), 1);  // 10 mod 3
  set_spent(state, {7, 0, 3});
  EXPECT_EQ(round_robin.choose(state), 1);
  kill(state, 0);
  EXPECT_EQ(round_robin.choose(state), 1);  // 10 mod 2 = 0: the first live one
  state.time = 11;
  EXPECT_EQ(round_robin.choose(state), 2);
}

TEST(FoundOrder, ProblemsOfMoreSkeletonsThanAStateHoldsInline) {
  const Problem problem = separate_skeletons(40);
  const Mdp mdp(problem);
  State state = mdp.start();
  ASSERT_EQ(state.spent.capacity(), 40U);
  FirstFoundAllocator first_found(mdp, 4);
  FoundOrderRoundRobinAllocator round_robin(mdp);
  // Skeletons 0 .. 29 abandoned at budget 4 or dead (every third), 30 .. 39 untried.
  for (int k = 0; k < 30; ++k) {
    state.spent[static_cast<std::size_t>(k)] = 4;
    if (k % 3 == 0) kill(state, k);
  }
  EXPECT_EQ(first_found.choose(state), 30);
  for (int k = 30; k < 40; ++k) state.spent[static_cast<std::size_t>(k)] = 4;
  EXPECT_EQ(first_found.choose(state), 1);  // budget 8; 0 is dead
  state.spent[39] = 3;
  EXPECT_EQ(first_found.choose(state), 39);
  // 10 of 0 .. 29 dead: 30 live, 1, 2, 4, 5, ..., 28, 29, then 30 .. 39. At CT = 17 the 17th
  // (from 0): 26; at CT = 25 the 25th: 35.
  state.time = 17;
  EXPECT_EQ(round_robin.choose(state), 26);
  state.time = 25;
  EXPECT_EQ(round_robin.choose(state), 35);
  // Sampled episodes on a random wide instance: the same for any thread count.
  const Problem wide = testing::wide_instance(7, 40, 3, 40);
  const Mdp wide_mdp(wide);
  for (const char* solver : {"first-found", "found-order-round-robin"}) {
    SCOPED_TRACE(solver);
    MonteCarloOptions options;
    options.episodes = 2'000;
    options.seed = 5;
    options.threads = 1;
    const MonteCarloResult one = run_monte_carlo(wide_mdp, make_allocator_factory(solver, wide_mdp), options);
    options.threads = 2;
    const MonteCarloResult two = run_monte_carlo(wide_mdp, make_allocator_factory(solver, wide_mdp), options);
    EXPECT_EQ(one.successes, two.successes);
  }
}

// The rules as a planner would state them, on the reference solver's own state: first-found
// tries budget, 2 budget, 4 budget, ... in turn, each in found order; round-robin lists the
// live skeletons and takes the (CT mod n)-th.
bool reference_dead(const Problem& problem, const testing::ReferenceSolver::Node& node, int k) {
  const auto slot = static_cast<std::size_t>(k);
  return node.refined[slot] == problem.skeleton_length(k) || node.time + 1 + node.execution[slot] > problem.deadline();
}

int reference_first_found(const Problem& problem, const testing::ReferenceSolver::Node& node, int budget) {
  for (int level_budget = budget;; level_budget *= 2) {
    bool live = false;
    for (int k = 0; k < problem.skeleton_count(); ++k) {
      if (reference_dead(problem, node, k)) continue;
      live = true;
      if (node.spent[static_cast<std::size_t>(k)] < level_budget) return k;
    }
    if (!live) return 0;
  }
}

int reference_round_robin(const Problem& problem, const testing::ReferenceSolver::Node& node) {
  std::vector<int> live;
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    if (!reference_dead(problem, node, k)) live.push_back(k);
  }
  return live.empty() ? 0 : live[static_cast<std::size_t>(node.time) % live.size()];
}

// Paper instance 1: the exact success of each equals the reference solver's value of the rule
// as written above, lies between 0 and the optimum, and Monte Carlo agrees with it.
TEST(FoundOrder, ExactSuccessOnInstanceOneMatchesAnIndependentRouteAndMonteCarlo) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  const double optimum = OptimalSolver(mdp).solve(mdp.start());
  struct Case {
    const char* name;
    ParameterValues values;
    testing::ReferenceSolver::Rule rule;
  };
  const std::vector<Case> cases = {
      {"first-found", {}, [&](const auto& node) { return reference_first_found(problem, node, 4); }},
      {"first-found", {{"budget", "2"}}, [&](const auto& node) { return reference_first_found(problem, node, 2); }},
      {"found-order-round-robin", {}, [&](const auto& node) { return reference_round_robin(problem, node); }},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.name) + (c.values.all().empty() ? "" : " budget 2"));
    const AllocatorFactory factory = make_allocator_factory(c.name, mdp, c.values);
    const auto allocator = factory();
    const double exact = evaluate_exactly(mdp, *allocator).success_probability;
    EXPECT_NEAR(exact, testing::ReferenceSolver(problem).value_of(c.rule), 1e-12);
    EXPECT_GT(exact, 0.0);
    EXPECT_LE(exact, optimum + 1e-12);
    // Sampled against exact, in standard errors of the exact value (as in evaluation_test).
    constexpr std::uint64_t kEpisodes = 20'000;
    MonteCarloOptions options;
    options.episodes = kEpisodes;
    options.seed = 31;
    const MonteCarloResult sampled = run_monte_carlo(mdp, factory, options);
    EXPECT_LE(std::abs(sampled.success_rate - exact), 4.0 * std::sqrt(exact * (1 - exact) / kEpisodes))
        << sampled.success_rate << " vs " << exact;
  }
}

}  // namespace
}  // namespace ontime
