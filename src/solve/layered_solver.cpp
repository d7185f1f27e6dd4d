// `solve_layered` and `split_plan` (include/ontime/solve/layered_solver.hpp): the checks, the
// choice between the whole tree and a split, and the merge of their intervals. The search itself
// is LayeredSearch (solve/layered/search.hpp and the files it names).
//
// The split mode: the root subtree with the largest clairvoyant chance alone is enumerated as a
// problem of its own, its keys flagged once a step went to the other subtrees, which are bounded
// by their best commit (below) and their clairvoyant chance (above) from every CT (WeakCluster);
// the result's choices and states are mapped back to the whole problem's skeletons. With
// SplitMode::fallback, a split runs only when a cap cut the whole tree, and each end of the
// interval is the tighter of the two (both hold the optimum).

#include "ontime/solve/layered_solver.hpp"

#include <algorithm>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/error.hpp"
#include "solve/expectimax.hpp"
#include "solve/layered/keys.hpp"
#include "solve/layered/search.hpp"

namespace ontime {
namespace {

// The skeletons under each first action, in order of their first action's first skeleton.
std::vector<std::vector<int>> root_subtrees(const Problem& problem) {
  std::vector<std::vector<int>> subtrees;
  std::vector<int> root_of(static_cast<std::size_t>(problem.action_count()), -1);
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    int& index = root_of[static_cast<std::size_t>(problem.action_at(k, 0))];
    if (index < 0) {
      index = static_cast<int>(subtrees.size());
      subtrees.emplace_back();
    }
    subtrees[static_cast<std::size_t>(index)].push_back(k);
  }
  return subtrees;
}

Problem subproblem(const Problem& problem, const std::vector<int>& skeletons, const std::string& part) {
  std::vector<Action> actions(problem.actions().begin(), problem.actions().end());
  std::vector<std::vector<int>> paths;
  std::vector<SkeletonReward> rewards;
  for (const int k : skeletons) {
    const auto path = problem.skeleton(k);
    paths.emplace_back(path.begin(), path.end());
    rewards.push_back(problem.reward(k));
  }
  return Problem(problem.name() + " (" + part + ")", problem.deadline(), problem.step_seconds(), std::move(actions),
                 std::move(paths), problem.description(), std::move(rewards),
                 std::vector<ExogenousChain>(problem.chains().begin(), problem.chains().end()));
}

}  // namespace

std::vector<int> split_plan(const Mdp& mdp) {
  const std::vector<std::vector<int>> subtrees = root_subtrees(mdp.problem());
  if (subtrees.size() < 2) return {};
  const ValueBounds bounds(mdp);
  const State start = mdp.start();
  std::size_t best = 0;
  double best_chance = -1.0;
  for (std::size_t i = 0; i < subtrees.size(); ++i) {
    const int k = subtrees[i].front();
    const double chance = bounds.group_upper(k, 0, 0, 0, start.time);
    if (chance > best_chance) {
      best_chance = chance;
      best = i;
    }
  }
  return subtrees[best];
}

namespace {

LayeredSolution solve_split(const Mdp& mdp, const LayeredSolveOptions& options, const std::vector<int>& kept) {
  const Problem& problem = mdp.problem();
  std::vector<int> bounded;
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    if (!std::binary_search(kept.begin(), kept.end(), k)) bounded.push_back(k);
  }
  const Problem strong = subproblem(problem, kept, "enumerated part");
  const Problem others = subproblem(problem, bounded, "bounded part");
  const Mdp strong_mdp(strong);
  const Mdp others_mdp(others);
  // The bounded subtrees, fresh, from every CT: their best commit and their clairvoyant chance.
  layered::WeakCluster weak;
  {
    const ValueBounds bounds(others_mdp);
    State fresh = others_mdp.start();
    for (Steps t = 0; t <= problem.deadline(); ++t) {
      fresh.time = static_cast<std::uint16_t>(t);
      const int choice = bounds.lower_choice(fresh);
      weak.lower.push_back(bounds.lower(fresh));
      weak.upper.push_back(bounds.upper(fresh));
      weak.commit.push_back(choice < 0 ? -1 : bounded[static_cast<std::size_t>(choice)]);
    }
  }
  LayeredSolution solution = layered::search_layers(strong_mdp, options, true, &weak);
  // Back to the whole problem's skeletons: the bounded ones stay at their start.
  const auto whole_choice = [&](int choice, int t) {
    if (choice == layered::kWeakChoice) return weak.commit[static_cast<std::size_t>(t)];
    return choice < 0 ? choice : kept[static_cast<std::size_t>(choice)];
  };
  solution.first_choice = whole_choice(solution.first_choice, 0);
  for (PolicyEntry& entry : solution.policy) {
    State whole = mdp.start();
    whole.time = entry.state.time;
    for (std::size_t i = 0; i < kept.size(); ++i) {
      const auto k = static_cast<std::size_t>(kept[i]);
      whole.refined[k] = entry.state.refined[i];
      whole.spent[k] = entry.state.spent[i];
      whole.execution[k] = entry.state.execution[i];
    }
    entry.choice = whole_choice(entry.choice, entry.state.time);
    entry.state = std::move(whole);
  }
  solution.split_kept = kept;
  solution.split_weak_upper = weak.upper.front();
  if (weak.upper.front() == 0.0 && solution.frontier_layer < 0 && solution.dropped == 0) {
    solution.exact = true;  // the bounded subtrees cannot succeed at all
    solution.upper = solution.lower;
  }
  solution.split_lower = solution.lower;
  solution.split_upper = solution.upper;
  solution.split_states = solution.states;
  solution.split_frontier_layer = std::exchange(solution.frontier_layer, -1);
  solution.split_stopped_by = std::exchange(solution.stopped_by, std::string());
  solution.split_layers = std::move(solution.layers);
  solution.layers.clear();
  return solution;
}

}  // namespace

LayeredSolution solve_layered(const Mdp& mdp, const LayeredSolveOptions& options) {
  detail::require_exact_size(mdp, "solve");
  if (!(options.tolerance >= 0.0 && options.tolerance <= 1.0)) {
    throw UsageError("solve: the tolerance must lie in [0, 1] (got " + std::to_string(options.tolerance) + ")");
  }
  // A tolerance drops a group by its clairvoyant chance, and a split bounds whole subtrees by
  // it. Under backtracking that bound counts every backtrack as a success (docs/theory.md), too
  // loose to drop anything by; with rewards it bounds a success probability, not a reward; with
  // chains or expiry it reads neither. Caps still give a certified interval at the frontier.
  const std::string unbounded = mdp.has_backtracking()        ? "backtracking (SPEC §7)"
                                : mdp.is_timed()              ? "chains or expiry (SPEC §9)"
                                : mdp.problem().has_rewards() ? "rewards (SPEC §8)"
                                                              : "";
  if (!unbounded.empty()) {
    if (options.tolerance > 0) throw UsageError("solve: a tolerance does not apply to an instance with " + unbounded);
    if (options.split == SplitMode::always) {
      throw UsageError("solve: a split does not apply to an instance with " + unbounded);
    }
    return layered::search_layers(mdp, options, false, nullptr);
  }
  if (options.split == SplitMode::always) {
    const std::vector<int> kept = split_plan(mdp);
    if (kept.empty()) {
      throw UsageError("solve: a split needs skeletons with at least two different first actions; all of " +
                       mdp.problem().name() + "'s begin with the same one");
    }
    return solve_split(mdp, options, kept);
  }
  LayeredSolution whole = layered::search_layers(mdp, options, false, nullptr);
  if (whole.frontier_layer < 0 || options.split == SplitMode::never) return whole;
  const std::vector<int> kept = split_plan(mdp);
  if (kept.empty()) return whole;
  // Both intervals hold the optimum: keep the tighter end of each, and the policy of the
  // higher lower end.
  LayeredSolution split = solve_split(mdp, options, kept);
  if (split.lower > whole.lower) {
    whole.lower = split.lower;
    whole.first_choice = split.first_choice;
    whole.policy = std::move(split.policy);
  }
  whole.upper = std::min(whole.upper, split.upper);
  whole.dropped += split.dropped;
  whole.split_kept = std::move(split.split_kept);
  whole.split_weak_upper = split.split_weak_upper;
  whole.split_lower = split.split_lower;
  whole.split_upper = split.split_upper;
  whole.split_states = split.split_states;
  whole.split_frontier_layer = split.split_frontier_layer;
  whole.split_stopped_by = std::move(split.split_stopped_by);
  whole.split_layers = std::move(split.split_layers);
  whole.states += split.split_states;
  whole.peak_memory_bytes = std::max(whole.peak_memory_bytes, split.peak_memory_bytes);
  whole.peak_disk_bytes = std::max(whole.peak_disk_bytes, split.peak_disk_bytes);
  return whole;
}

}  // namespace ontime
