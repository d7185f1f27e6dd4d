// Acting while planning (SPEC §10): the bounds of ConcurrentValueBounds against the exact optimum
// on random states of random instances; the devoted policy's exact value against the lower bound's
// term; ConcurrentSearch's answers against ConcurrentSolver, searched in full and cut short;
// solve_concurrent (`solve --method search`) against the memoised solver, to the bit.
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
#include "ontime/util/error.hpp"
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

// An instance of data/instances/chains.
Problem chain_instance(const std::string& name) {
  return load_problem(testing::source_path("data/instances/chains/" + name + ".json"));
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

// States met by `walks` random walks from the start (uniform useful moves, outcomes drawn by
// their probabilities), the running ones only.
std::vector<ConcurrentState> random_states(const ConcurrentMdp& mdp, std::uint64_t seed, int walks) {
  SplitMix64 generator(seed);
  std::vector<ConcurrentState> states;
  for (int walk = 0; walk < walks; ++walk) {
    ConcurrentState state = mdp.start();
    for (;;) {
      const std::vector<Move> moves = mdp.useful_moves(state);
      if (moves.empty()) break;
      states.push_back(state);
      const Move move = moves[generator() % moves.size()];
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
struct SandwichCounts {
  int states = 0;
  int open = 0;
  int raised = 0;
};
SandwichCounts check_sandwich(int count, const std::function<Problem(std::uint64_t)>& make) {
  SandwichCounts counts;
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    const ConcurrentMdp mdp(make(seed));
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
      bool alone = true;
      for (int m = 0; m < problem.skeleton_count(); ++m) {
        const int length = problem.skeleton_length(m);
        if (m != k && length <= problem.skeleton_length(k) &&
            problem.action_at(m, length - 1) == problem.action_at(k, length - 1) &&
            (length < problem.skeleton_length(k) || m < k)) {
          alone = false;
        }
      }
      if (!alone || !ConcurrentMdp::is_live(mdp.start(), k)) continue;
      const auto policy = [&](const ConcurrentState& state) -> Move {
        if (!ConcurrentMdp::is_live(state, k)) return {};
        const int depth = mdp.executed_depth(state);
        if (ConcurrentMdp::robot_left(state) == 0 && ConcurrentMdp::refined(state, k) > depth) {
          return {problem.action_at(k, depth), ConcurrentMdp::kWait};
        }
        if (ConcurrentMdp::refined(state, k) < problem.skeleton_length(k)) return {-1, k};
        return {};
      };
      ConcurrentSolver evaluation(mdp, policy);
      EXPECT_NEAR(evaluation.solve(mdp.start()), devoted.value(mdp.start(), k), kSearchRounding)
          << "seed " << seed << " skeleton " << k;
      ++checked;
    }
  }
  EXPECT_GT(checked, count / 2);
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

// The exact search (branch and bound over the trials' intervals) gives the memoised solver's value
// and first move to the bit, solving fewer states.
TEST(ConcurrentSearchSolve, TheValueAndTheFirstMoveAreTheMemoisedSolversToTheBit) {
  int fewer = 0;
  const auto check = [&](const Problem& problem, const std::string& label) {
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
    fewer += solution.solved < solver.states() ? 1 : 0;
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
    return std::pair<std::uint64_t, std::size_t>{solution.solved, solver.states()};
  };
  const int count = testing::repetitions_to_check(150);
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    check(search_instance(seed + 7000), "seed " + std::to_string(seed));
  }
  std::printf("the search solved fewer states on %d of %d random instances\n", fewer, count);
  for (const char* name : {"instance1", "instance2", "instance3", "instance4", "instance5"}) {
    check(testing::paper_instance(name), name);
  }
  // Where the bounds are tight the search solves a small share: 3,940 of 269,605 states here.
  const auto [solved, states] = check(testing::navigation_with_deadline(14), "navigation at 14 steps");
  EXPECT_LT(solved * 20, states);
  // With chains and expiry (SPEC §9): starts whose execution a chain draws are chance moves.
  for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(count); ++seed) {
    check(timed_instance(seed + 7000), "chains, seed " + std::to_string(seed));
  }
  check(chain_instance("meeting-through-the-queue"), "meeting-through-the-queue");
}

// Cut short by its cap or its stop, or asked for a gap, the search gives an interval around the
// optimum (as wide as asked at most, for a gap).
TEST(ConcurrentSearchSolve, CutShortItsIntervalHoldsTheOptimum) {
  const Problem problem = testing::navigation_with_deadline(14);
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
  for (const ConcurrentSolveOptions& options : {capped, stopped, gap}) {
    calls = 0;
    const ConcurrentSolution solution = solve_concurrent(mdp, options);
    ASSERT_FALSE(solution.exact) << options.max_states << " " << options.gap;
    EXPECT_LE(solution.lower, optimum + kSearchRounding) << solution.stopped_by;
    EXPECT_GE(solution.upper, optimum - kSearchRounding) << solution.stopped_by;
    EXPECT_LT(solution.lower, solution.upper) << solution.stopped_by;
  }
  const ConcurrentSolution narrowed = solve_concurrent(mdp, gap);
  EXPECT_EQ(narrowed.stopped_by, "the gap");
  EXPECT_LE(narrowed.upper - narrowed.lower, 0.05);
  EXPECT_EQ(solve_concurrent(mdp, capped).stopped_by, "the state cap");
  calls = 0;
  EXPECT_EQ(solve_concurrent(mdp, stopped).stopped_by, "the stop condition");
}

TEST(ConcurrentSearchSolve, RefusesWhatItsBoundsDoNotTake) {
  const ConcurrentMdp backtracking(testing::with_backtracking(testing::random_instance(3, 4, 3, 10), 3));
  EXPECT_THROW(solve_concurrent(backtracking, search_options()), UsageError);
  // The cup through the door gives up (SPEC §7) as well as following its chains.
  const ConcurrentMdp cup(chain_instance("cup-through-the-door"));
  EXPECT_THROW(solve_concurrent(cup, search_options()), UsageError);
}

// P(union of the devoted successes) by brute force: every joint draw of the actions' planning
// times (effort until found) and execution times, each skeleton's devoted timeline (its actions
// found one after another, each run as soon as it is found and the robot is free), the draws in
// which some skeleton finishes by the deadline. Written from the definition, not from the tree.
double union_by_enumeration(const Problem& problem) {
  const Steps deadline = problem.deadline();
  struct Draw {
    Steps found;  // kNever: never
    Steps runs;   // kNever: too slow or never
    double probability;
  };
  std::vector<std::vector<Draw>> draws(static_cast<std::size_t>(problem.action_count()));
  for (int a = 0; a < problem.action_count(); ++a) {
    const Action& action = problem.action(a);
    double found_mass = 0.0;
    for (Steps t = 1; t <= deadline; ++t) {
      found_mass += action.planning.pmf(t);
      double run_mass = 0.0;
      for (Steps x = 0; x <= deadline; ++x) {
        run_mass += action.execution.pmf(x);
        if (action.planning.pmf(t) * action.execution.pmf(x) > 0)
          draws[static_cast<std::size_t>(a)].push_back({t, x, action.planning.pmf(t) * action.execution.pmf(x)});
      }
      if (1.0 - run_mass > 1e-15)
        draws[static_cast<std::size_t>(a)].push_back({t, kNever, action.planning.pmf(t) * (1.0 - run_mass)});
    }
    if (1.0 - found_mass > 1e-15) draws[static_cast<std::size_t>(a)].push_back({kNever, kNever, 1.0 - found_mass});
  }
  std::vector<std::size_t> pick(draws.size(), 0);
  double total = 0.0;
  for (;;) {
    double probability = 1.0;
    for (std::size_t a = 0; a < draws.size(); ++a) probability *= draws[a][pick[a]].probability;
    bool any = false;
    for (int k = 0; k < problem.skeleton_count() && !any; ++k) {
      std::int64_t found = 0, free = 0;
      bool fits = true;
      for (int j = 0; j < problem.skeleton_length(k) && fits; ++j) {
        const Draw& draw = draws[static_cast<std::size_t>(problem.action_at(k, j))]
                                [pick[static_cast<std::size_t>(problem.action_at(k, j))]];
        if (draw.found == kNever || draw.runs == kNever) {
          fits = false;
          break;
        }
        found += draw.found;
        free = std::max(free, found) + draw.runs;
        fits = found <= deadline && free <= deadline;
      }
      any = fits;
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
