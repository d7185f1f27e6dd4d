#include "ontime/solve/concurrent_clairvoyant_bound.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "ontime/util/error.hpp"

namespace ontime {

ConcurrentClairvoyantBound::ConcurrentClairvoyantBound(const ConcurrentMdp& mdp)
    : mdp_(&mdp), deadline_(mdp.deadline()), backtracking_(mdp.has_backtracking()) {
  if (mdp.is_timed()) {
    throw UsageError(mdp.problem().name() +
                     ": the clairvoyant bound acting while planning (SPEC §10) does not take exogenous chains or "
                     "expiry (SPEC §9) yet");
  }
  const Problem& problem = mdp.problem();
  const auto actions = static_cast<std::size_t>(problem.action_count());
  children_.assign(actions + 1, {});
  ends_.assign(actions, 0);
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    const int length = problem.skeleton_length(k);
    for (int j = 0; j < length; ++j) {
      const int action = problem.action_at(k, j);
      std::vector<int>& siblings = children_[j == 0 ? actions : static_cast<std::size_t>(problem.action_at(k, j - 1))];
      if (std::find(siblings.begin(), siblings.end(), action) == siblings.end()) siblings.push_back(action);
    }
    ends_[static_cast<std::size_t>(problem.action_at(k, length - 1))] = 1;
  }
  // With backtracking: whether an action below each node (the roots: index A) may give up,
  // deepest first.
  gives_up_below_.assign(actions + 1, 0);
  if (backtracking_) {
    std::vector<int> nodes;
    for (int a = 0; a < problem.action_count(); ++a) {
      if (problem.position(a) >= 0) nodes.push_back(a);
    }
    std::stable_sort(nodes.begin(), nodes.end(),
                     [&problem](int x, int y) { return problem.position(x) > problem.position(y); });
    nodes.push_back(problem.action_count());
    for (const int v : nodes) {
      for (const int c : children_[static_cast<std::size_t>(v)]) {
        if (!problem.culprits(c).empty() || gives_up_below_[static_cast<std::size_t>(c)] != 0)
          gives_up_below_[static_cast<std::size_t>(v)] = 1;
      }
    }
  }
  // With backtracking the robot's free step runs to D + 1 (past the deadline, a give-up still counts).
  const auto side = static_cast<std::size_t>(deadline_) + 1;
  free_side_ = side + (backtracking_ ? 1 : 0);
  memo_.assign(actions * side * free_side_, -1.0);
}

// The recursion of below, expect, fresh and at_state goes one action deeper per level: at most a
// skeleton's length deep, whatever the deadline.
template <class ChildValue>
// NOLINTNEXTLINE(misc-no-recursion)
double ConcurrentClairvoyantBound::below(int v, Steps free, ChildValue&& child) const {
  if (free > deadline_ && !gives_up_below(v)) return 0.0;
  // A skeleton ending at v ends the episode there (the longer ones through v need at least as long).
  if (v >= 0 && ends_[static_cast<std::size_t>(v)] != 0 && free <= deadline_) return 1.0;
  const std::vector<int>& next = children_[v < 0 ? children_.size() - 1 : static_cast<std::size_t>(v)];
  double none = 1.0;
  for (const int c : next) none *= 1.0 - child(c);
  return 1.0 - none;
}

template <class After>
// NOLINTNEXTLINE(misc-no-recursion)
double ConcurrentClairvoyantBound::expect(int a, Steps spent, Steps time, Steps free, After&& after) const {
  const Mdp& model = mdp_->plan_first_mdp();
  double total = 0.0;
  double survival = 1.0;  // not found in the steps so far
  for (Steps found = time + 1, effort = spent; found <= deadline_ && effort < deadline_; ++found, ++effort) {
    const double now = survival * model.hazard(a, effort);
    const double back = backtracking_ ? survival * model.backtrack_hazard(a, effort) : 0.0;
    survival -= now;
    if (backtracking_) {
      survival -= back;
      total += back;  // a give-up ends the relaxed episode: an event of the union
    }
    if (now <= 0.0) continue;
    const Steps start = std::max(free, found);
    for (const Mdp::ExecutionOutcome& outcome : model.execution_outcomes(a)) {
      std::int64_t finish = std::int64_t{start} + outcome.steps;
      if (finish > deadline_) {
        if (!gives_up_below(a)) continue;
        finish = deadline_ + 1;  // too slow, but a give-up below may still come
      }
      total += now * outcome.probability * after(found, static_cast<Steps>(finish));
    }
  }
  return total;
}

// NOLINTNEXTLINE(misc-no-recursion)
double ConcurrentClairvoyantBound::fresh(int v, Steps time, Steps free) {
  const auto side = static_cast<std::size_t>(deadline_) + 1;
  double& memo = memo_[(static_cast<std::size_t>(v) * side + static_cast<std::size_t>(time)) * free_side_ +
                       static_cast<std::size_t>(free)];
  if (memo >= 0.0) return memo;
  const double value = expect(v, 0, time, free, [&](Steps found, Steps finish) {  // NOLINT(misc-no-recursion)
    return below(v, finish, [&](int c) { return fresh(c, found, finish); });      // NOLINT(misc-no-recursion)
  });
  memo = value;
  return value;
}

// NOLINTNEXTLINE(misc-no-recursion)
double ConcurrentClairvoyantBound::at_state(const ConcurrentState& state, int v, Steps time, Steps free) {
  const Problem& problem = mdp_->problem();
  const int position = problem.position(v);
  // The live skeletons through v agree on its status: refined with them all, or their next action.
  int through = -1;
  for (const int k : problem.members(v)) {
    if (ConcurrentMdp::is_live(state, k)) {
      through = k;
      break;
    }
  }
  if (through < 0) return 0.0;  // no live skeleton goes this way
  const auto child = [&](Steps found, Steps finish) {
    return [&, found, finish](int c) { return at_state(state, c, found, finish); };  // NOLINT(misc-no-recursion)
  };
  const int refined = ConcurrentMdp::refined(state, through);
  if (position < refined) {
    const std::uint16_t word = mdp_->execution(state, v);
    std::int64_t finish = std::int64_t{free} + word;
    if (finish > deadline_) {
      if (!gives_up_below(v)) return 0.0;
      finish = deadline_ + 1;
    }
    return below(v, static_cast<Steps>(finish), child(time, static_cast<Steps>(finish)));
  }
  if (position == refined) {
    return expect(
        v, mdp_->spent(state, through), time, free, [&](Steps found, Steps finish) {  // NOLINT(misc-no-recursion)
          return below(v, finish, [&](int c) { return fresh(c, found, finish); });    // NOLINT(misc-no-recursion)
        });
  }
  return fresh(v, time, free);
}

double ConcurrentClairvoyantBound::union_probability(const ConcurrentState& state) {
  if (!mdp_->any_live(state)) return 0.0;
  const Steps time = ConcurrentMdp::time(state);
  std::int64_t free = std::int64_t{time} + ConcurrentMdp::robot_left(state);
  const int executed = ConcurrentMdp::executed(state);
  if (free > deadline_) {
    if (!gives_up_below(executed)) return 0.0;
    free = deadline_ + 1;
  }
  const std::vector<int>& next = children_[executed < 0 ? children_.size() - 1 : static_cast<std::size_t>(executed)];
  double none = 1.0;
  for (const int c : next) none *= 1.0 - at_state(state, c, time, static_cast<Steps>(free));
  return 1.0 - none;
}

}  // namespace ontime
