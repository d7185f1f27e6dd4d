// Acting while planning (SPEC §10): the bounds of ConcurrentValueBounds against the exact optimum
// on random states of random instances, with and without backtracking (SPEC §7) and chains (§9); the
// devoted policy's exact value against the lower bound's term; ConcurrentSearch's answers against ConcurrentSolver,
// searched in full and cut short; solve_concurrent (`solve --method search`) against the memoised solver, to the bit.
#include "ontime/solve/concurrent_search.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/solve/concurrent_clairvoyant_bound.hpp"
#include "ontime/solve/concurrent_contiguous_success.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/solve/concurrent_value_bounds.hpp"
#include "ontime/util/random.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

using Move = ConcurrentMdp::Move;

ConcurrentSolveOptions search_options() {
  ConcurrentSolveOptions options;
  options.method = ConcurrentSolveOptions::Method::search;
  return options;
}

// Rounding of sums of a few dozen products of probabilities.
constexpr double kSearchRounding = 1e-12;

Problem search_instance(std::uint64_t seed) {
  const Problem problem = testing::random_instance(seed, 4, 4, 12);
  return seed % 3 == 0 ? testing::with_random_rewards(problem, seed) : problem;
}

// With exogenous chains, chain-dependent executions and expiry (SPEC §9); half with rewards.
Problem timed_instance(std::uint64_t seed) {
  return testing::with_random_chains(testing::random_instance(seed + 5000, 4, 3, 10), seed, seed % 2 == 0);
}

Problem restore_instance(std::uint64_t seed);

// With backtracking (SPEC §7; an instance without an action after a first one has none), a third
// with rewards; every fourth shaped for a restore (restore_instance).
Problem backtracking_instance(std::uint64_t seed) {
  const Problem problem = seed % 4 == 3
                              ? restore_instance(seed)
                              : testing::with_backtracking(testing::random_instance(seed + 4000, 4, 4, 11), seed);
  return seed % 3 == 0 ? testing::with_random_rewards(problem, seed) : problem;
}

// With backtracking, chains, chain-dependent executions and expiry (SPEC §7 with §9); every other
// one shaped for a restore.
Problem timed_backtracking_instance(std::uint64_t seed) {
  return testing::with_random_chains(
      seed % 2 == 0 ? restore_instance(seed + 500)
                    : testing::with_backtracking(testing::random_instance(seed + 6000, 4, 3, 10), seed + 1000),
      seed, seed % 4 < 2);
}

// Where a give-up may restore a culprit refined while the robot runs: a (short planning, long
// execution), then b, then c, which finds its motion or gives up blaming b (or a); a second
// skeleton a, d. Random masses and times, deadline 10 to 14.
Problem restore_instance(std::uint64_t seed) {
  SplitMix64 generator(seed);
  const auto step = [&](int first, int last) {
    return std::to_string(first + static_cast<int>(generator() % static_cast<std::uint64_t>(last - first + 1)));
  };
  const auto weight = [&] { return std::to_string(0.1 + 0.4 * uniform01(generator)); };
  const std::string found = weight(), gives_up = weight(), blames_b = std::to_string(0.5 + 0.5 * uniform01(generator));
  const std::string text = R"({"deadline": )" + step(10, 14) + R"(, "actions": {
    "a": {"planning": {"pmf": {")" +
                           step(1, 2) + R"(": 1}}, "execution": {"pmf": {")" + step(2, 5) + R"(": 1}}},
    "b": {"planning": {"pmf": {"1": 0.5, ")" +
                           step(2, 3) + R"(": 0.5}}, "execution": {"pmf": {")" + step(0, 3) +
                           R"(": 1}}},
    "c": {"planning": {"pmf": {"1": )" +
                           found + R"(}}, "execution": {"pmf": {")" + step(1, 3) + R"(": 1}},
          "backtrack": {"pmf": {")" +
                           step(1, 2) + R"(": )" + gives_up + R"(}},
          "culprits": {"b": )" +
                           blames_b + R"(, "a": )" + std::to_string(1.0 - std::stod(blames_b)) + R"(}},
    "d": {"planning": {"pmf": {")" +
                           step(1, 6) + R"(": 0.7}}, "execution": {"pmf": {")" + step(1, 4) + R"(": 1}}}},
    "skeletons": [["a", "b", "c"], ["a", "d"]]})";
  return parse_problem(text, "restore-" + std::to_string(seed));
}

// An instance of data/instances/chains.
Problem chain_instance(const std::string& name) {
  return load_problem(testing::source_path("data/instances/chains/" + name + ".json"));
}

// An instance of data/instances (a path below it).
Problem data_instance(const std::string& path) {
  return load_problem(testing::source_path("data/instances/" + path + ".json"));
}

// The outcomes of `move` in `state`: visit(probability, ends, reward, next) per outcome.
template <class Visitor>
void for_each_outcome(const ConcurrentMdp& mdp, const ConcurrentState& state, const Move& move, Visitor&& visit) {
  if (move.is_start()) {
    mdp.for_each_start_outcome(state, move.start, [&](double probability, const ConcurrentMdp::StartOutcome& outcome) {
      visit(probability, outcome.ends, outcome.reward, outcome.next);
    });
    return;
  }
  mdp.for_each_step_outcome(state, move.refine, [&](double probability, const ConcurrentState& next) {
    visit(probability, false, 0.0, next);
  });
}

// Chooses a walk's move among the useful ones (not empty).
using WalkMove = std::function<Move(const ConcurrentState&, const std::vector<Move>&, SplitMix64&)>;

// States met by `walks` random walks from the start (uniform useful moves, or those `choose` makes;
// outcomes drawn by their probabilities), the running ones only.
std::vector<ConcurrentState> random_states(const ConcurrentMdp& mdp, std::uint64_t seed, int walks,
                                           const WalkMove& choose = nullptr) {
  SplitMix64 generator(seed);
  std::vector<ConcurrentState> states;
  for (int walk = 0; walk < walks; ++walk) {
    ConcurrentState state = mdp.start();
    for (;;) {
      const std::vector<Move> moves = mdp.useful_moves(state);
      if (moves.empty()) break;
      states.push_back(state);
      const Move move = choose ? choose(state, moves, generator) : moves[generator() % moves.size()];
      if (move.is_start()) {
        // An execution a chain draws when the action starts (SPEC §9): the world's draw.
        const Steps drawn = mdp.sample_start_execution(state, move.start, generator);
        ConcurrentMdp::StartOutcome outcome = mdp.start_action(state, move.start, drawn);
        if (outcome.ends) break;
        state = std::move(outcome.next);
        continue;
      }
      double u = uniform01(generator);
      ConcurrentState chosen;
      mdp.for_each_step_outcome(state, move.refine, [&](double probability, const ConcurrentState& next) {
        if (chosen.empty() || u >= 0.0) chosen = next;
        u -= probability;
      });
      state = std::move(chosen);
    }
  }
  return states;
}

// The policy devoted to skeleton k: the planner refines k alone, the robot starts k's next action
// as soon as it is refined and the robot is idle; once k is dropped the planner idles.
ConcurrentSolver::Policy devoted_policy(const ConcurrentMdp& mdp, int k) {
  return [&mdp, k](const ConcurrentState& state) -> Move {
    const Problem& problem = mdp.problem();
    if (!ConcurrentMdp::is_live(state, k)) return {};
    const int depth = mdp.executed_depth(state);
    if (ConcurrentMdp::robot_left(state) == 0 && ConcurrentMdp::refined(state, k) > depth) {
      return {problem.action_at(k, depth), ConcurrentMdp::kWait};
    }
    if (ConcurrentMdp::refined(state, k) < problem.skeleton_length(k)) return {-1, k};
    return {};
  };
}

// Whether live skeleton k is the one whose last start ends the episode under its devoted policy:
// no other live skeleton is a proper prefix of it or spells it again with a lower index.
bool eligible(const ConcurrentMdp& mdp, const ConcurrentState& state, int k) {
  const Problem& problem = mdp.problem();
  for (int m = 0; m < problem.skeleton_count(); ++m) {
    const int length = problem.skeleton_length(m);
    if (m != k && ConcurrentMdp::is_live(state, m) && length <= problem.skeleton_length(k) &&
        problem.action_at(m, length - 1) == problem.action_at(k, length - 1) &&
        (length < problem.skeleton_length(k) || m < k)) {
      return false;
    }
  }
  return true;
}

// Q*(state, move) from the exact solver.
double exact_q(const ConcurrentMdp& mdp, ConcurrentSolver& solver, const ConcurrentState& state, const Move& move) {
  double q = 0.0;
  for_each_outcome(mdp, state, move, [&](double probability, bool ends, double reward, const ConcurrentState& next) {
    q += probability * (ends ? reward : solver.solve(next));
  });
  return q;
}

// lower <= V* <= upper at the states of random walks over `count` instances made by `make`: the
// states checked, those with the ends apart and those with a lower end above 0.
// Also the instances with backtracking (SPEC §7).
struct SandwichCounts {
  int states = 0;
  int open = 0;
  int raised = 0;
  int backtracking = 0;
};
SandwichCounts check_sandwich(int count, const std::function<Problem(std::uint64_t)>& make) {
  SandwichCounts counts;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const ConcurrentMdp mdp(make(seed));
    counts.backtracking += mdp.has_backtracking() ? 1 : 0;
    ConcurrentSolver solver(mdp);
    ConcurrentValueBounds bounds(mdp);
    for (const ConcurrentState& state : random_states(mdp, seed, 4)) {
      const double optimum = solver.solve(state);
      const ConcurrentValueBounds::Interval interval = bounds.bounds(state);
      EXPECT_LE(interval.lower, optimum + kSearchRounding) << "seed " << seed;
      EXPECT_GE(interval.upper, optimum - kSearchRounding) << "seed " << seed;
      ++counts.states;
      counts.open += interval.upper - interval.lower > 1e-9 ? 1 : 0;
      counts.raised += interval.lower > 0.0 ? 1 : 0;
    }
  }
  return counts;
}

TEST(ConcurrentValueBounds, SandwichTheOptimumOnRandomStates) {
  const int count = testing::repetitions_to_check(120);
  const SandwichCounts counts = check_sandwich(count, search_instance);
  // Hundreds of states, and dozens of them with the bounds apart (the check sees real intervals).
  std::printf("%d states, %d open\n", counts.states, counts.open);
  EXPECT_GT(counts.states, 4 * count);
  EXPECT_GT(counts.open, count / 3);
}

// With chains and expiry (SPEC §9) the upper end is the union bound of the relaxed problem and the
// lower end the best start that ends the episode now.
TEST(ConcurrentValueBounds, SandwichTheOptimumOnRandomStatesWithChains) {
  const int count = testing::repetitions_to_check(120);
  const SandwichCounts counts =
      check_sandwich(count, [](std::uint64_t seed) { return timed_instance(seed).with_acting(Acting::concurrent); });
  // Hundreds of states, most with the bounds apart, and some with a lower end above 0.
  std::printf("%d states, %d open, %d with a lower end above 0\n", counts.states, counts.open, counts.raised);
  EXPECT_GT(counts.states, 4 * count);
  EXPECT_GT(counts.open, count);
  EXPECT_GT(counts.raised, count / 10);
}

// With backtracking (SPEC §7): below, the devoted policies' exact values (give-ups and all); above,
// the union bound of the relaxation in which the first give-up ends the episode with the largest
// reward left.
TEST(ConcurrentValueBounds, SandwichTheOptimumOnRandomStatesWithBacktracking) {
  const int count = testing::repetitions_to_check(120);
  const SandwichCounts counts = check_sandwich(count, backtracking_instance);
  std::printf("%d states, %d open, %d with a lower end above 0, %d instances with backtracking\n", counts.states,
              counts.open, counts.raised, counts.backtracking);
  EXPECT_GT(counts.backtracking, count * 3 / 4);
  EXPECT_GT(counts.states, 4 * count);
  EXPECT_GT(counts.open, count);
  EXPECT_GT(counts.raised, count);
}

// With backtracking and chains or expiry (SPEC §7 with §9): the relaxations of both, and the best
// ending start below.
TEST(ConcurrentValueBounds, SandwichTheOptimumOnRandomStatesWithBacktrackingAndChains) {
  const int count = testing::repetitions_to_check(80);
  const SandwichCounts counts = check_sandwich(
      count, [](std::uint64_t seed) { return timed_backtracking_instance(seed).with_acting(Acting::concurrent); });
  std::printf("%d states, %d open, %d with a lower end above 0, %d instances with backtracking\n", counts.states,
              counts.open, counts.raised, counts.backtracking);
  EXPECT_GT(counts.backtracking, count / 2);
  EXPECT_GT(counts.states, 4 * count);
  EXPECT_GT(counts.open, count);
  EXPECT_GT(counts.raised, count / 10);
}

// A hand case of the relaxation: a (found at step 1, runs 1 step) then c, whose first step finds
// it (1/4), or gives up blaming a (1/4), or neither (1/2; nothing after), deadline 3. Devoted: a
// runs 1..2, c found at 2 runs 2..3: success 1/4; the give-up at 2 finds a executed, so c is
// blocked: the devoted value (and V*: keeping a unstarted, c found at 2 would end at 4) is 1/4,
// the relaxation's reward 1/4 and give-up chance 1/4, the upper end 1/2.
TEST(ConcurrentValueBounds, WithBacktrackingAGiveUpCountsTheLargestRewardLeft) {
  const Problem problem = parse_problem(R"({"deadline": 3,
    "actions": {"a": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"1": 1}}},
                "c": {"planning": {"pmf": {"1": 0.25}}, "execution": {"pmf": {"1": 1}},
                      "backtrack": {"pmf": {"1": 0.25}}, "culprits": {"a": 1}}},
    "skeletons": [["a", "c"]]})",
                                        "give-up");
  const ConcurrentMdp mdp(problem);
  ConcurrentContiguousSuccess devoted(mdp, Aggregation::self, ConcurrentContiguousSuccess::Timing::relax);
  const ConcurrentContiguousSuccess::GiveUpRelaxed relaxed = devoted.give_up_relaxed(mdp.start(), 0);
  EXPECT_NEAR(relaxed.reward, 0.25, 1e-15);
  EXPECT_NEAR(relaxed.give_up, 0.25, 1e-15);
  ConcurrentValueBounds bounds(mdp);
  const ConcurrentValueBounds::Interval interval = bounds.bounds(mdp.start());
  EXPECT_NEAR(interval.lower, 0.25, 1e-15);
  EXPECT_NEAR(interval.upper, 0.5, 1e-15);
  ConcurrentSolver solver(mdp);
  EXPECT_NEAR(solver.solve(mdp.start()), 0.25, 1e-15);
}

// The lower bound's term for skeleton k is the exact value of the policy it names: refine k alone,
// start k's next action as soon as it is refined and the robot is idle.
TEST(ConcurrentValueBounds, TheDevotedValueIsThePolicysExactValue) {
  const int count = testing::repetitions_to_check(100);
  int checked = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const Problem problem = search_instance(seed);
    const ConcurrentMdp mdp(problem);
    ConcurrentContiguousSuccess devoted(mdp, Aggregation::self);
    for (int k = 0; k < problem.skeleton_count(); ++k) {
      // Only skeletons no other one is a prefix of (or spells again with a lower index).
      if (!ConcurrentMdp::is_live(mdp.start(), k) || !eligible(mdp, mdp.start(), k)) continue;
      ConcurrentSolver evaluation(mdp, devoted_policy(mdp, k));
      EXPECT_NEAR(evaluation.solve(mdp.start()), devoted.value(mdp.start(), k), kSearchRounding)
          << "seed " << seed << " skeleton " << k;
      ++checked;
    }
  }
  EXPECT_GT(checked, count / 2);
}

// With backtracking (SPEC §7), the lower end's term from any state: at the states of random walks
// (uniform moves, and walks along skeleton k that start its refined actions only half of the time,
// so that refined culprits wait for a busy robot) of random instances and of instances shaped for a
// restore, the devoted policy's exact value (the solver's policy mode) for every eligible skeleton.
TEST(ConcurrentValueBounds, WithBacktrackingTheDevotedValueIsThePolicysExactValueAtAnyState) {
  const int count = testing::repetitions_to_check(150);
  int checked = 0, raised = 0, waiting = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const ConcurrentMdp mdp(seed % 2 == 0 ? backtracking_instance(seed + 100) : restore_instance(seed));
    const Problem& problem = mdp.problem();
    ConcurrentContiguousSuccess devoted(mdp, Aggregation::self);
    for (int k = 0; k < mdp.skeleton_count(); ++k) {
      ConcurrentSolver evaluation(mdp, devoted_policy(mdp, k));
      const WalkMove along_k = [&](const ConcurrentState& state, const std::vector<Move>& moves, SplitMix64& random) {
        const Move devoted_move = devoted_policy(mdp, k)(state);
        // A step is named by the lowest skeleton of the group sharing the action.
        const auto same = [&](const Move& move) {
          if (move.is_start() || devoted_move.is_start() || move.refine < 0 || devoted_move.refine < 0) {
            return move == devoted_move;
          }
          return problem.action_at(move.refine, ConcurrentMdp::refined(state, move.refine)) ==
                 problem.action_at(k, ConcurrentMdp::refined(state, k));
        };
        const auto found = std::find_if(moves.begin(), moves.end(), same);
        if (found == moves.end() || (devoted_move.is_start() && random() % 2 == 0)) {
          return moves[random() % moves.size()];
        }
        return *found;
      };
      std::vector<ConcurrentState> states = random_states(mdp, seed + 900, 2);
      for (ConcurrentState& state : random_states(mdp, seed + 1900, 6, along_k)) states.push_back(std::move(state));
      for (const ConcurrentState& state : states) {
        if (!ConcurrentMdp::is_live(state, k) || !eligible(mdp, state, k)) continue;
        const double value = devoted.value(state, k);
        EXPECT_NEAR(value, evaluation.solve(state), kSearchRounding) << "seed " << seed << " skeleton " << k;
        ++checked;
        raised += value > 0.0 ? 1 : 0;
        // A culprit of k refined and not started while the robot runs: a give-up may restore it.
        for (int p = mdp.executed_depth(state); p < ConcurrentMdp::refined(state, k); ++p) {
          waiting += problem.culprit_slot(problem.action_at(k, p)) >= 0 && ConcurrentMdp::robot_left(state) > 0 ? 1 : 0;
        }
      }
    }
  }
  std::printf("%d states checked, %d with a value above 0, %d culprits waiting for a busy robot\n", checked, raised,
              waiting);
  EXPECT_GT(checked, 10 * count);
  EXPECT_GT(raised, 3 * count);
  EXPECT_GT(waiting, count / 2);
}

// The lower end's term from a state where a culprit is refined and waits for the robot: a (found at
// step 1, runs 4 steps), b (found at 2, runs 1), then c, whose every attempt finds it or gives up
// blaming b, w.p. 1/2 each (deadline 12). At CT 2, a running until 5 and b refined: a give-up at 3
// or at 5 finds b not started (at 5 it is seen before the start), so b is refined again (1 step)
// and c tried again; at 7 b started at 6, and a give-up blocks c. 1/2 + 1/4 + 1/8 = 0.875.
TEST(ConcurrentValueBounds, WithBacktrackingTheDevotedValueRestoresACulpritRefinedBeforeTheState) {
  const Problem problem = parse_problem(R"({"deadline": 12,
    "actions": {"a": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"4": 1}}},
                "b": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"1": 1}}},
                "c": {"planning": {"pmf": {"1": 0.5}}, "execution": {"pmf": {"1": 1}},
                      "backtrack": {"pmf": {"1": 0.5}}, "culprits": {"b": 1}}},
    "skeletons": [["a", "b", "c"]]})",
                                        "restore");
  const ConcurrentMdp mdp(problem);
  const Observation found_a{.refined = true, .execution = 4};
  const Observation found_b{.refined = true, .execution = 1};
  const ConcurrentState refined_a = mdp.step(mdp.start(), 0, found_a);
  const ConcurrentState running_a = mdp.start_action(refined_a, 0).next;
  const ConcurrentState state = mdp.step(running_a, 0, found_b);
  ASSERT_EQ(ConcurrentMdp::refined(state, 0), 2);
  ASSERT_EQ(ConcurrentMdp::robot_left(state), 3);
  ConcurrentContiguousSuccess devoted(mdp, Aggregation::self);
  EXPECT_NEAR(devoted.value(state, 0), 0.875, 1e-15);
  ConcurrentSolver evaluation(mdp, devoted_policy(mdp, 0));
  EXPECT_NEAR(evaluation.solve(state), 0.875, 1e-15);
  ConcurrentValueBounds bounds(mdp);
  EXPECT_NEAR(bounds.lower(state), 0.875, 1e-15);
}

// Without a limit the search closes at the states of random walks over `count` instances made by
// `make`: its interval is V*, and its move attains it. The states checked.
int check_search_closes(int count, const std::function<Problem(std::uint64_t)>& make) {
  int searched = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const ConcurrentMdp mdp(make(seed));
    ConcurrentSolver solver(mdp);
    ConcurrentSearch search(mdp);
    for (const ConcurrentState& state : random_states(mdp, seed + 500, 2)) {
      const double optimum = solver.solve(state);
      const ConcurrentSearchResult result = search.search(state, nullptr);
      EXPECT_TRUE(result.exact) << "seed " << seed;
      EXPECT_NEAR(result.lower, optimum, kSearchRounding) << "seed " << seed;
      EXPECT_NEAR(result.upper, optimum, kSearchRounding) << "seed " << seed;
      if (mdp.certain_success(state)) continue;
      EXPECT_NEAR(exact_q(mdp, solver, state, result.move), optimum, kSearchRounding) << "seed " << seed;
      ++searched;
    }
  }
  return searched;
}

TEST(ConcurrentSearch, WithoutALimitItsMoveAttainsTheOptimum) {
  const int count = testing::repetitions_to_check(80);
  EXPECT_GT(check_search_closes(count, search_instance), 2 * count);
}

TEST(ConcurrentSearch, WithBacktrackingWithoutALimitItsMoveAttainsTheOptimum) {
  const int count = testing::repetitions_to_check(80);
  EXPECT_GT(check_search_closes(count, backtracking_instance), 2 * count);
  EXPECT_GT(check_search_closes(count,
                                [](std::uint64_t seed) {
                                  return timed_backtracking_instance(seed + 300).with_acting(Acting::concurrent);
                                }),
            count);
}

TEST(ConcurrentSearch, WithChainsWithoutALimitItsMoveAttainsTheOptimum) {
  const int count = testing::repetitions_to_check(80);
  EXPECT_GT(check_search_closes(
                count, [](std::uint64_t seed) { return timed_instance(seed + 300).with_acting(Acting::concurrent); }),
            2 * count);
}

TEST(ConcurrentSearch, CutShortItsGapBoundsTheLoss) {
  const int count = testing::repetitions_to_check(80);
  int cut = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const Problem problem = testing::random_instance(seed + 2000, 5, 4, 20);
    const ConcurrentMdp mdp(problem);
    ConcurrentSolver solver(mdp);
    const ConcurrentState start = mdp.start();
    if (!mdp.any_live(start)) continue;
    for (const std::uint64_t budget : {1, 2, 4}) {
      ConcurrentSearch search(mdp);
      const ConcurrentSearchResult result = search.search(start, [&](std::uint64_t work) { return work >= budget; });
      const double optimum = solver.solve(start);
      EXPECT_GE(result.upper, optimum - kSearchRounding) << "seed " << seed;
      EXPECT_LE(result.lower, exact_q(mdp, solver, start, result.move) + kSearchRounding) << "seed " << seed;
      cut += result.exact ? 0 : 1;
    }
  }
  EXPECT_GT(cut, count / 10);
}

// The trials draw their outcomes from the seed of the last clear(): the same seed walks the same
// states to the same interval; another walks others, its interval as certified (navigation cut to
// 12 steps, searches cut short).
TEST(ConcurrentSearch, TheTrialsDrawFromTheirSeed) {
  const ConcurrentMdp mdp(testing::navigation_with_deadline(12));
  const ConcurrentState start = mdp.start();
  const double optimum = ConcurrentSolver(mdp).solve(start);
  const auto budget = [](std::uint64_t work) { return work >= 2000; };
  ConcurrentSearch search(mdp);
  search.clear(7);
  const ConcurrentSearchResult first = search.search(start, budget);
  const std::uint64_t first_records = search.size();
  ASSERT_FALSE(first.exact);
  search.clear(7);
  const ConcurrentSearchResult again = search.search(start, budget);
  EXPECT_EQ(again.lower, first.lower);
  EXPECT_EQ(again.upper, first.upper);
  EXPECT_EQ(again.move, first.move);
  EXPECT_EQ(search.size(), first_records);
  int differ = 0;
  for (std::uint64_t seed = 8; seed < 12; ++seed) {
    search.clear(seed);
    const ConcurrentSearchResult other = search.search(start, budget);
    EXPECT_LE(other.lower, optimum + kSearchRounding) << "seed " << seed;
    EXPECT_GE(other.upper, optimum - kSearchRounding) << "seed " << seed;
    differ += search.size() != first_records || other.lower != first.lower || other.upper != first.upper ? 1 : 0;
  }
  EXPECT_GE(differ, 3);
}

// The exact search (branch and bound over the trials' intervals) on `problem` gives the memoised
// solver's value and first move to the bit, solving no more states; so does branch and bound on
// the bounds alone. The states solved by the search and by the memoised solver.
std::pair<std::uint64_t, std::size_t> check_search_is_memoised(const Problem& problem, const std::string& label) {
  const ConcurrentMdp mdp(problem);
  ConcurrentSolver solver(mdp);
  const double optimum = solver.solve(mdp.start());
  const ConcurrentSolution solution = solve_concurrent(mdp, search_options());
  EXPECT_TRUE(solution.exact) << label;
  EXPECT_EQ(solution.lower, optimum) << label;  // bit for bit
  EXPECT_EQ(solution.upper, optimum) << label;
  if (mdp.any_live(mdp.start()) && !mdp.certain_success(mdp.start())) {
    EXPECT_EQ(solution.first, *solver.best_move(mdp.start())) << label;
  }
  EXPECT_LE(solution.solved, solver.states()) << label;
  // Branch and bound on the bounds alone (no trials: looser intervals, so the move of the
  // largest lower end is often not the best and more moves are left out or solved).
  ConcurrentSolver bounded(mdp);
  ConcurrentValueBounds heuristic(mdp);
  bounded.set_bounds([&](const ConcurrentState& state) {
    const ConcurrentValueBounds::Interval interval = heuristic.bounds(state);
    return std::pair<double, double>{interval.lower - ConcurrentSearch::kBoundSlack,
                                     interval.upper + ConcurrentSearch::kBoundSlack};
  });
  EXPECT_EQ(bounded.solve(mdp.start()), optimum) << label;
  if (mdp.any_live(mdp.start()) && !mdp.certain_success(mdp.start())) {
    EXPECT_EQ(*bounded.best_move(mdp.start()), *solver.best_move(mdp.start())) << label;
  }
  return {solution.solved, solver.states()};
}

TEST(ConcurrentSearchSolve, TheValueAndTheFirstMoveAreTheMemoisedSolversToTheBit) {
  int fewer = 0;
  const auto check = [&](const Problem& problem, const std::string& label) {
    const auto counts = check_search_is_memoised(problem, label);
    fewer += counts.first < counts.second ? 1 : 0;
    return counts;
  };
  const int count = testing::repetitions_to_check(150);
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    check(search_instance(seed + 7000), "seed " + std::to_string(seed));
  }
  std::printf("the search solved fewer states on %d of %d random instances\n", fewer, count);
  for (const char* name : {"instance1", "instance2", "instance3", "instance4", "instance5"}) {
    check(testing::paper_instance(name), name);
  }
  // Where the bounds are tight the search solves a small share: 4,588 of 269,897 states here.
  const auto [solved, states] = check(testing::navigation_with_deadline(14), "navigation at 14 steps");
  EXPECT_LT(solved * 20, states);
  // With chains and expiry (SPEC §9): starts whose execution a chain draws are chance moves.
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    check(timed_instance(seed + 7000), "chains, seed " + std::to_string(seed));
  }
  check(chain_instance("meeting-through-the-queue"), "meeting-through-the-queue");
}

// With backtracking (SPEC §7), with chains and expiry too (§9), and (below) on the instances of
// data/instances that give up.
TEST(ConcurrentSearchSolve, WithBacktrackingTheValueAndTheFirstMoveAreTheMemoisedSolversToTheBit) {
  const int count = testing::repetitions_to_check(150);
  int backtracking = 0, fewer = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const Problem problem = backtracking_instance(seed + 7000);
    backtracking += problem.has_backtracking() ? 1 : 0;
    const auto [solved, states] = check_search_is_memoised(problem, "seed " + std::to_string(seed));
    fewer += solved < states ? 1 : 0;
  }
  std::printf("the search solved fewer states on %d of %d random instances\n", fewer, count);
  EXPECT_GT(backtracking, count * 3 / 4);
  const int timed = testing::repetitions_to_check(60);
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(timed); ++seed) {
    check_search_is_memoised(timed_backtracking_instance(seed + 7000), "chains, seed " + std::to_string(seed));
  }
}

TEST(ConcurrentSearchSolve, OnTheInstancesThatGiveUpTheValueAndTheFirstMoveAreTheMemoisedSolversToTheBit) {
  for (const std::string path : {"kitchen-grasps", "backtracking/grasp-and-place", "chains/cup-through-the-door"}) {
    const Problem problem = data_instance(path);
    ASSERT_TRUE(problem.has_backtracking()) << path;
    const auto [solved, states] = check_search_is_memoised(problem, path);
    std::printf("%s: the search solved %llu of %zu states\n", path.c_str(), static_cast<unsigned long long>(solved),
                states);
  }
}

// Cut short by its cap or its stop, or asked for a gap, the search gives an interval around the
// optimum of `problem` (as wide as asked at most, for a gap).
void check_cut_short(const Problem& problem) {
  const ConcurrentMdp mdp(problem);
  ConcurrentSolver solver(mdp);
  const double optimum = solver.solve(mdp.start());
  ConcurrentSolveOptions capped = search_options();
  capped.max_states = 200;
  ConcurrentSolveOptions stopped = search_options();
  int calls = 0;
  stopped.stop = [&calls] { return ++calls > 1; };
  ConcurrentSolveOptions gap = search_options();
  gap.gap = 0.05;
  const std::vector<std::pair<ConcurrentSolveOptions, std::string>> runs{
      {capped, "the state cap"}, {stopped, "the stop condition"}, {gap, "the gap"}};
  for (const auto& [options, stopped_by] : runs) {
    calls = 0;
    const ConcurrentSolution solution = solve_concurrent(mdp, options);
    ASSERT_FALSE(solution.exact) << problem.name() << " " << stopped_by;
    EXPECT_EQ(solution.stopped_by, stopped_by) << problem.name();
    EXPECT_LE(solution.lower, optimum + kSearchRounding) << problem.name() << " " << stopped_by;
    EXPECT_GE(solution.upper, optimum - kSearchRounding) << problem.name() << " " << stopped_by;
    EXPECT_LT(solution.lower, solution.upper) << problem.name() << " " << stopped_by;
    if (options.gap > 0) {
      EXPECT_LE(solution.upper - solution.lower, options.gap) << problem.name();
    }
  }
}

TEST(ConcurrentSearchSolve, CutShortItsIntervalHoldsTheOptimum) {
  check_cut_short(testing::navigation_with_deadline(14));
  // With backtracking (SPEC §7): the kitchen whose placements may blame their grasps.
  check_cut_short(data_instance("kitchen-grasps"));
}

// P(union of the devoted successes) by brute force: every joint draw of the actions' planning
// times (effort until found) and execution times, each skeleton's devoted timeline (its actions
// found one after another, each run as soon as it is found and the robot is free), the draws in
// which some skeleton finishes by the deadline. With backtracking (SPEC §7) an attempt may also
// give up (one attempt per action: the relaxation in which the first give-up ends the episode), and
// a timeline that reaches a give-up by the deadline counts too. Written from the definition, not
// from the tree.
double union_by_enumeration(const Problem& problem) {
  const Steps deadline = problem.deadline();
  struct Draw {
    Steps found;  // the attempt's end; kNever: never
    Steps runs;   // kNever: too slow or never
    double probability;
    bool gives_up = false;
  };
  std::vector<std::vector<Draw>> draws(static_cast<std::size_t>(problem.action_count()));
  for (int a = 0; a < problem.action_count(); ++a) {
    const Action& action = problem.action(a);
    double ended_mass = 0.0;
    for (Steps t = 1; t <= deadline; ++t) {
      ended_mass += action.planning.pmf(t) + action.backtrack.pmf(t);
      if (action.backtrack.pmf(t) > 0)
        draws[static_cast<std::size_t>(a)].push_back({t, kNever, action.backtrack.pmf(t), true});
      double run_mass = 0.0;
      for (Steps x = 0; x <= deadline; ++x) {
        run_mass += action.execution.pmf(x);
        if (action.planning.pmf(t) * action.execution.pmf(x) > 0)
          draws[static_cast<std::size_t>(a)].push_back({t, x, action.planning.pmf(t) * action.execution.pmf(x)});
      }
      if (1.0 - run_mass > 1e-15)
        draws[static_cast<std::size_t>(a)].push_back({t, kNever, action.planning.pmf(t) * (1.0 - run_mass)});
    }
    if (1.0 - ended_mass > 1e-15) draws[static_cast<std::size_t>(a)].push_back({kNever, kNever, 1.0 - ended_mass});
  }
  std::vector<std::size_t> pick(draws.size(), 0);
  double total = 0.0;
  for (;;) {
    double probability = 1.0;
    for (std::size_t a = 0; a < draws.size(); ++a) probability *= draws[a][pick[a]].probability;
    bool any = false;
    for (int k = 0; k < problem.skeleton_count() && !any; ++k) {
      std::int64_t found = 0, free = 0;
      bool refined = true;
      for (int j = 0; j < problem.skeleton_length(k); ++j) {
        const Draw& draw = draws[static_cast<std::size_t>(problem.action_at(k, j))]
                                [pick[static_cast<std::size_t>(problem.action_at(k, j))]];
        if (draw.found == kNever || found + draw.found > deadline) {
          refined = false;
          break;
        }
        found += draw.found;
        if (draw.gives_up) {
          any = true;  // a give-up by the deadline ends the relaxed episode
          break;
        }
        free = draw.runs == kNever ? std::int64_t{deadline} + 1 : std::max(free, found) + draw.runs;
      }
      any = any || (refined && free <= deadline);
    }
    if (any) total += probability;
    std::size_t a = 0;
    while (a < pick.size() && ++pick[a] == draws[a].size()) pick[a++] = 0;
    if (a == pick.size()) break;
  }
  return total;
}

// The clairvoyant bound is the chance of the union of the devoted successes: the brute force's at
// the start of small random instances, the devoted value itself where one skeleton is live, never
// below the optimum, never above the union bound.
TEST(ConcurrentClairvoyantBound, IsTheChanceThatSomeDevotedPolicySucceeds) {
  const int count = testing::repetitions_to_check(200);
  int shared = 0, alone = 0, states = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const Problem small = testing::random_instance(seed + 9000, 3, 2, 7);
    if (small.action_count() <= 4) {
      const ConcurrentMdp mdp(small);
      ConcurrentClairvoyantBound bound(mdp);
      EXPECT_NEAR(bound.union_probability(mdp.start()), union_by_enumeration(small), 1e-12) << "seed " << seed;
      for (int a = 0; a < small.action_count(); ++a) shared += small.members(a).size() > 1 ? 1 : 0;
    }
    const Problem problem = testing::random_instance(seed, 4, 4, 12);
    const ConcurrentMdp mdp(problem);
    ConcurrentSolver solver(mdp);
    ConcurrentClairvoyantBound bound(mdp);
    ConcurrentContiguousSuccess devoted(mdp, Aggregation::self);
    for (const ConcurrentState& state : random_states(mdp, seed + 300, 3)) {
      const double union_chance = bound.union_probability(state);
      EXPECT_GE(union_chance, solver.solve(state) - kSearchRounding) << "seed " << seed;
      double sum = 0.0;
      int live = 0, only = -1;
      for (int k = 0; k < problem.skeleton_count(); ++k) {
        if (!ConcurrentMdp::is_live(state, k)) continue;
        sum += devoted.value(state, k);
        ++live;
        only = k;
      }
      EXPECT_LE(union_chance, sum + kSearchRounding) << "seed " << seed;
      if (live == 1) {
        EXPECT_NEAR(union_chance, devoted.value(state, only), kSearchRounding) << "seed " << seed;
        ++alone;
      }
      ++states;
    }
  }
  // The brute force met shared actions (so the tree's conditioning was checked), and the single
  // skeleton case came up often.
  EXPECT_GT(shared, count / 10);
  EXPECT_GT(alone, count / 2);
  EXPECT_GT(states, 3 * count);
}

// With backtracking (SPEC §7): the chance of the union of the relaxed devoted events (a success,
// or a give-up by the deadline), the brute force's at the start of small random instances, and
// never below the optimum at random states.
TEST(ConcurrentClairvoyantBound, WithBacktrackingIsTheChanceThatSomeDevotedPolicySucceedsOrGivesUp) {
  const int count = testing::repetitions_to_check(200);
  int enumerated = 0, states = 0;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const Problem small = testing::with_backtracking(testing::random_instance(seed + 9000, 3, 3, 7), seed);
    // Where no skeleton can finish the state is worth 0 and the bound says so (terminal).
    if (small.action_count() <= 4 && small.has_backtracking() &&
        ConcurrentMdp(small).any_live(ConcurrentMdp(small).start())) {
      const ConcurrentMdp mdp(small);
      ConcurrentClairvoyantBound bound(mdp);
      EXPECT_NEAR(bound.union_probability(mdp.start()), union_by_enumeration(small), 1e-12) << "seed " << seed;
      ++enumerated;
    }
    const ConcurrentMdp mdp(backtracking_instance(seed));
    ConcurrentSolver solver(mdp);
    ConcurrentClairvoyantBound bound(mdp);
    for (const ConcurrentState& state : random_states(mdp, seed + 300, 3)) {
      EXPECT_GE(bound.union_probability(state), solver.solve(state) - kSearchRounding) << "seed " << seed;
      ++states;
    }
  }
  EXPECT_GT(enumerated, count / 10);
  EXPECT_GT(states, 3 * count);
}

// Two skeletons sharing a first action: the union bound counts their common success twice, the
// tree once. a (found in 1 step w.p. 1/2 per step, run in 1) then b or c (each found in 1 step
// w.p. 1/2 only, run in 1), deadline 3: a at step 1 (1/2) leaves one step for b or c: 1 - 1/4;
// a at step 2 leaves none. The chance is 1/2 * 3/4 = 3/8; each devoted value is 1/4, summing to 1/2.
TEST(ConcurrentClairvoyantBound, CountsASharedPrefixOnce) {
  const Problem problem = parse_problem(R"({"deadline": 3,
    "actions": {"a": {"planning": {"pmf": {"1": 0.5, "2": 0.5}}, "execution": {"pmf": {"1": 1}}},
                "b": {"planning": {"pmf": {"1": 0.5}}, "execution": {"pmf": {"1": 1}}},
                "c": {"planning": {"pmf": {"1": 0.5}}, "execution": {"pmf": {"1": 1}}}},
    "skeletons": [["a", "b"], ["a", "c"]]})",
                                        "shared");
  const ConcurrentMdp mdp(problem);
  ConcurrentClairvoyantBound bound(mdp);
  EXPECT_NEAR(bound.union_probability(mdp.start()), 3.0 / 8, 1e-15);
  ConcurrentContiguousSuccess devoted(mdp, Aggregation::self);
  EXPECT_NEAR(devoted.value(mdp.start(), 0) + devoted.value(mdp.start(), 1), 0.5, 1e-15);
  EXPECT_NEAR(union_by_enumeration(problem), 3.0 / 8, 1e-15);
}

}  // namespace
}  // namespace ontime
