// dp-rerun when the robot acts while planning (SPEC §10): Eq. (1) with the robot's backlog, the
// eager commit rule, and its exact value by the solver's policy mode, against the optimum and
// against episodes drawn from the model.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "ontime/allocators/dp_rerun.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/solve/concurrent_contiguous_success.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

struct Figures {
  double policy;
  double optimum;
};

// The policy's exact value, by the solver's policy mode.
double policy_value(const Problem& problem) {
  const ConcurrentMdp mdp(problem);
  ConcurrentDpRerunAllocator policy(mdp);
  ConcurrentSolver evaluation(mdp, [&](const ConcurrentState& state) { return policy.choose(state); });
  return evaluation.solve(mdp.start());
}

Figures figures(const Problem& problem) {
  const ConcurrentMdp mdp(problem);
  ConcurrentSolver optimal(mdp);
  return {policy_value(problem), optimal.solve(mdp.start())};
}

// The mean reward of `episodes` episodes of the policy, each drawn from the model's outcomes.
double sampled_value(const Problem& problem, std::uint64_t episodes, std::uint64_t seed) {
  const ConcurrentMdp mdp(problem);
  ConcurrentDpRerunAllocator policy(mdp);
  SplitMix64 generator(seed);
  double total = 0;
  std::vector<std::pair<double, ConcurrentState>> outcomes;
  for (std::uint64_t episode = 0; episode < episodes; ++episode) {
    ConcurrentState state = mdp.start();
    while (mdp.any_live(state)) {
      const ConcurrentMdp::Move move = policy.choose(state);
      if (move.is_start()) {
        ConcurrentMdp::StartOutcome started = mdp.start_action(state, move.start);
        if (started.ends) {
          total += started.reward;
          break;
        }
        state = std::move(started.next);
        continue;
      }
      if (ConcurrentMdp::time(state) >= mdp.deadline()) break;
      outcomes.clear();
      mdp.for_each_step_outcome(state, move.refine, [&](double probability, const ConcurrentState& next) {
        outcomes.emplace_back(probability, next);
      });
      state = outcomes[sample_index(
                           outcomes.size(), [&](std::size_t i) { return outcomes[i].first; }, generator)]
                  .second;
    }
  }
  return total / static_cast<double>(episodes);
}

TEST(ConcurrentDpRerun, ComesCloseToTheOptimumOnThePaperInstancesAndNavigation) {
  // Instance 2 is dp-rerun's own shortfall: 0.69 against 0.72, plan-first as here (Table I).
  for (const std::string name : {"instance1", "instance3", "instance4", "instance5"}) {
    const Figures got = figures(testing::paper_instance(name));
    EXPECT_LE(got.policy, got.optimum + 1e-12) << name;
    EXPECT_GE(got.policy, 0.98 * got.optimum) << name;
  }
  const Figures second = figures(testing::paper_instance("instance2"));
  EXPECT_NEAR(second.policy, 0.69, 1e-12);
  EXPECT_NEAR(second.optimum, 0.72, 1e-12);
  const Figures navigation = figures(testing::navigation_with_deadline(14));
  EXPECT_LE(navigation.policy, navigation.optimum + 1e-12);
  EXPECT_GE(navigation.policy, 0.98 * navigation.optimum);
  // At its own deadline (22 steps) the optimum is the search's (`ontime solve
  // data/instances/navigation.json --act concurrent --method search`, 34 s; the memoised value to
  // the bit, tests/solve/concurrent_search_test.cpp); dp-rerun's policy, 0.876381, is within 0.04%.
  const Problem own_deadline = testing::navigation_with_deadline(22);
  const double policy = policy_value(own_deadline);
  EXPECT_LE(policy, 0.8766933308900257 + 1e-12);
  EXPECT_GE(policy, 0.98 * 0.8766933308900257);
}

// Whether another skeleton is a prefix of skeleton k, or k spelled again with a lower index: the
// episode then ends through it when its last action starts (SPEC §10), which Eq. (1) of k does not
// count.
bool ends_through_another(const Problem& problem, int k) {
  const int length = problem.skeleton_length(k);
  for (int m = 0; m < problem.skeleton_count(); ++m) {
    const int prefix = problem.skeleton_length(m);
    if (m == k || prefix > length || problem.action_at(m, prefix - 1) != problem.action_at(k, prefix - 1)) continue;
    if (prefix < length || m < k) return true;
  }
  return false;
}

// The exact value of the policy devoted to skeleton k (SPEC §10): the planner refines k alone, the
// robot starts each of k's actions as soon as it is refined and the robot is free; once k is dropped
// the planner idles and nothing starts.
double devoted_value(const ConcurrentMdp& mdp, int k) {
  const Problem& problem = mdp.problem();
  ConcurrentSolver evaluation(mdp, [&](const ConcurrentState& state) -> ConcurrentMdp::Move {
    if (!ConcurrentMdp::is_live(state, k)) return {};
    const int depth = mdp.executed_depth(state);
    const int refined = ConcurrentMdp::refined(state, k);
    if (ConcurrentMdp::robot_left(state) == 0 && refined > depth)
      return {problem.action_at(k, depth), ConcurrentMdp::kWait};
    if (refined < problem.skeleton_length(k)) return {-1, k};
    return {};
  });
  return evaluation.solve(mdp.start());
}

TEST(ConcurrentDpRerun, EquationOneWithGiveUpsIsTheDevotedPolicysExactValue) {
  // Eq. (1) acting while planning with the give-up term and aggregation self, from the start and
  // from states the devoted policy reaches, against the exact value of that policy (the solver's
  // policy mode, written from the MDP, not from Eq. (1)), on random instances with backtracking.
  int with_give_ups = 0;
  int later_states = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(testing::repetitions_to_check(300)); ++seed) {
    const Problem problem = testing::with_backtracking(
        testing::random_instance(seed, 1 + static_cast<int>(seed % 3), 4, 6 + static_cast<Steps>(seed % 5)),
        seed + 500);
    const ConcurrentMdp mdp(problem);
    if (!mdp.has_backtracking()) continue;  // no action after a first one
    ++with_give_ups;
    ConcurrentContiguousSuccess values(mdp, Aggregation::self);
    for (int k = 0; k < mdp.skeleton_count(); ++k) {
      if (ends_through_another(problem, k)) continue;
      EXPECT_NEAR(values.value(mdp.start(), k), devoted_value(mdp, k), 1e-12) << "seed " << seed << " skeleton " << k;
    }
    // A state after a few steps devoted to skeleton 0, where what is refined and executed matters.
    ConcurrentState state = mdp.start();
    SplitMix64 generator(seed);
    std::vector<std::pair<double, ConcurrentState>> outcomes;
    for (int move = 0; move < 4 && ConcurrentMdp::is_live(state, 0) && ConcurrentMdp::time(state) < mdp.deadline();
         ++move) {
      const int depth = mdp.executed_depth(state);
      if (ConcurrentMdp::robot_left(state) == 0 && ConcurrentMdp::refined(state, 0) > depth) {
        const ConcurrentMdp::StartOutcome started = mdp.start_action(state, problem.action_at(0, depth));
        if (started.ends) break;
        state = started.next;
        continue;
      }
      if (ConcurrentMdp::refined(state, 0) >= problem.skeleton_length(0)) break;
      outcomes.clear();
      mdp.for_each_step_outcome(
          state, 0, [&](double probability, const ConcurrentState& next) { outcomes.emplace_back(probability, next); });
      state = outcomes[sample_index(
                           outcomes.size(), [&](std::size_t i) { return outcomes[i].first; }, generator)]
                  .second;
    }
    if (!ConcurrentMdp::is_live(state, 0) || ends_through_another(problem, 0)) continue;
    ++later_states;
    ConcurrentSolver from_state(mdp, [&](const ConcurrentState& at) -> ConcurrentMdp::Move {
      if (!ConcurrentMdp::is_live(at, 0)) return {};
      const int depth = mdp.executed_depth(at);
      const int refined = ConcurrentMdp::refined(at, 0);
      if (ConcurrentMdp::robot_left(at) == 0 && refined > depth)
        return {problem.action_at(0, depth), ConcurrentMdp::kWait};
      if (refined < problem.skeleton_length(0)) return {-1, 0};
      return {};
    });
    EXPECT_NEAR(values.value(state, 0), from_state.solve(state), 1e-12) << "seed " << seed << " later state";
  }
  EXPECT_GT(with_give_ups, testing::repetitions_to_check(300) / 2);
  EXPECT_GT(later_states, with_give_ups / 4);
}

TEST(ConcurrentDpRerun, AGiveUpRestoresACulpritTheRobotHasNotStarted) {
  // a is found at step 1 and runs until 5; b is found at 2 and waits for the robot; each attempt
  // on c finds it or gives up blaming b, w.p. 1/2. A give-up at 3 or at 5 finds b not started
  // (at 5 the give-up is seen before the start): b is refined again (1 step) and c tried again.
  // At 7, b started at 6: the give-up blocks c. Success: 1/2 + 1/4 + 1/8 = 0.875.
  const Problem problem = parse_problem(R"({
    "deadline": 12,
    "actions": {
      "a": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"4": 1}}},
      "b": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"1": 1}}},
      "c": {"planning": {"pmf": {"1": 0.5}}, "execution": {"pmf": {"1": 1}},
            "backtrack": {"pmf": {"1": 0.5}}, "culprits": {"b": 1}}
    },
    "skeletons": [["a", "b", "c"]]
  })",
                                        "restore");
  const ConcurrentMdp mdp(problem);
  ConcurrentContiguousSuccess values(mdp, Aggregation::self);
  EXPECT_NEAR(values.value(mdp.start(), 0), 0.875, 1e-15);
  EXPECT_NEAR(devoted_value(mdp, 0), 0.875, 1e-15);
}

TEST(ConcurrentDpRerun, ItsExactValueIsWhatItsEpisodesEarn) {
  for (const Problem& problem : {testing::paper_instance("instance2"), testing::navigation_with_deadline(14),
                                 testing::with_random_rewards(testing::paper_instance("instance3"), 5)}) {
    const double exact = policy_value(problem);
    // Fewer under the sanitizers (ONTIME_TEST_SHARE), the bound below widening with them.
    const auto episodes = static_cast<std::uint64_t>(testing::repetitions_to_check(20'000));
    const double sampled = sampled_value(problem, episodes, 7);
    // Rewards lie in [0, 1], so their variance is at most the mean's v(1 - v).
    const double error = std::sqrt(exact * (1 - exact) / static_cast<double>(episodes));
    EXPECT_NEAR(sampled, exact, 4 * error + 1e-12) << problem.name();
  }
}

}  // namespace
}  // namespace ontime
