#pragma once
// An independent implementation of SPEC §7 (backtracking) for tests, written from the
// specification and sharing no code with the library's Mdp: its state is one entry per action
// (refined with its motion's execution time, or the effort of its current attempt), a skeleton's
// ET is summed from its refined actions, and a backtrack un-refines the culprit and every action
// below it. Two computations on it:
//
// - optimum(): expectimax, branching every step on the attempt's hazards (found, backtrack to
//   each culprit, not yet), over every skeleton with an action left;
// - value_of(rule): the success probability of a stationary rule by enumerating the hidden
//   worlds: each attempt's whole outcome (the step it ends, a motion with its execution or a
//   backtrack with its culprit, or never) is drawn when the attempt starts, then the episode runs
//   deterministically until the attempt ends.
//
// Exponential; for instances of a few actions and deadlines of a few steps.

#include <algorithm>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "ontime/model/problem.hpp"

namespace ontime::testing {

class BacktrackingReference {
 public:
  struct Node {
    int time = 0;
    std::vector<long> motion;  // per action: its motion's execution steps, or -1 while unrefined
    std::vector<int> effort;   // per action: steps of its current attempt
    auto operator<=>(const Node&) const = default;
  };
  // A stationary rule on this state: the skeleton to spend the step on (one with an action left).
  using Rule = std::function<int(const BacktrackingReference&, const Node&)>;

  explicit BacktrackingReference(const Problem& problem) : problem_(problem) {}

  double optimum() {
    memo_.clear();
    return best(start());
  }

  double value_of(const Rule& rule) {
    // Hidden outcomes of each action's current attempt: end step (0: not drawn yet), motion or
    // culprit.
    World world;
    world.end.assign(static_cast<std::size_t>(problem_.action_count()), 0);
    world.execution.assign(world.end.size(), 0);
    world.culprit.assign(world.end.size(), -1);
    return run(rule, start(), world);
  }

  // The action skeleton k refines next, or -1.
  int next_action(const Node& node, int k) const {
    for (const int action : problem_.skeleton(k)) {
      if (node.motion[static_cast<std::size_t>(action)] < 0) return action;
    }
    return -1;
  }

  const Problem& problem() const { return problem_; }

 private:
  struct World {
    std::vector<int> end;  // 0: not drawn; -1: never ends
    std::vector<long> execution;
    std::vector<int> culprit;
  };

  Node start() const {
    Node node;
    node.motion.assign(static_cast<std::size_t>(problem_.action_count()), -1);
    node.effort.assign(static_cast<std::size_t>(problem_.action_count()), 0);
    return node;
  }

  long execution_of(const Node& node, int k) const {
    long total = 0;
    for (const int action : problem_.skeleton(k)) total += node.motion[static_cast<std::size_t>(action)];
    return total;
  }

  // After a motion for `action` at time node.time: whether some skeleton it completes meets the
  // deadline.
  bool succeeded(const Node& node, int action) const {
    for (int k = 0; k < problem_.skeleton_count(); ++k) {
      if (problem_.skeleton(k).back() != action) continue;
      if (next_action(node, k) < 0 && node.time + execution_of(node, k) <= problem_.deadline()) return true;
    }
    return false;
  }

  void unrefine_below(Node& node, int culprit) const {
    for (int a = 0; a < problem_.action_count(); ++a) {
      bool below = a == culprit;
      for (int up = problem_.parent(a); up >= 0 && !below; up = problem_.parent(up)) below = up == culprit;
      if (!below) continue;
      node.motion[static_cast<std::size_t>(a)] = -1;
      node.effort[static_cast<std::size_t>(a)] = 0;
    }
  }

  static double mass(const Distribution& d, int t) { return t >= 0 ? d.pmf(t) : 0.0; }

  // P(the attempt has not ended after `effort` steps).
  double alive(int action, int effort) const {
    const Action& a = problem_.action(action);
    double ended = 0;
    for (int t = 1; t <= effort; ++t) ended += mass(a.planning, t) + mass(a.backtrack, t);
    return 1.0 - ended;
  }

  double best(const Node& node) {
    if (node.time >= problem_.deadline()) return 0.0;
    if (const auto known = memo_.find(node); known != memo_.end()) return known->second;
    double value = 0;
    for (int k = 0; k < problem_.skeleton_count(); ++k) {
      const int action = next_action(node, k);
      if (action < 0) continue;
      value = std::max(value, expected(node, action));
    }
    memo_[node] = value;
    return value;
  }

  double expected(const Node& node, int action) {
    const Action& a = problem_.action(action);
    const auto slot = static_cast<std::size_t>(action);
    const double remaining = alive(action, node.effort[slot]);
    const int t = node.effort[slot] + 1;
    const double found = remaining > 0 ? mass(a.planning, t) / remaining : 0.0;
    const double back = remaining > 0 ? mass(a.backtrack, t) / remaining : 0.0;
    double value = 0;
    Node next = node;
    ++next.time;
    if (found + back < 1.0) {
      Node waiting = next;
      ++waiting.effort[slot];
      value += (1.0 - found - back) * best(waiting);
    }
    for (long x = 0; found > 0 && x <= problem_.deadline() + 1; ++x) {
      const double px = x <= problem_.deadline() ? a.execution.pmf(static_cast<Steps>(x))
                                                 : 1.0 - a.execution.cdf(problem_.deadline());
      if (px <= 0) continue;
      Node refined = next;
      refined.motion[slot] = x;
      refined.effort[slot] = 0;
      value += found * px * (succeeded(refined, action) ? 1.0 : best(refined));
    }
    for (const Culprit& culprit : a.culprits) {
      if (back <= 0 || culprit.probability <= 0) continue;
      Node undone = next;
      unrefine_below(undone, problem_.find_action(culprit.id));
      value += back * culprit.probability * best(undone);
    }
    return value;
  }

  double run(const Rule& rule, Node node, World world) {
    while (node.time < problem_.deadline()) {
      bool any = false;
      for (int k = 0; k < problem_.skeleton_count() && !any; ++k) any = next_action(node, k) >= 0;
      if (!any) return 0.0;
      const int action = next_action(node, rule(*this, node));
      const auto slot = static_cast<std::size_t>(action);
      if (world.end[slot] == 0) return draw(rule, node, world, action);  // a new attempt: every world of it
      ++node.time;
      ++node.effort[slot];
      if (world.end[slot] != node.effort[slot]) continue;
      world.end[slot] = 0;
      if (world.culprit[slot] < 0) {
        node.motion[slot] = world.execution[slot];
        node.effort[slot] = 0;
        if (succeeded(node, action)) return 1.0;
      } else {
        const int culprit = world.culprit[slot];
        unrefine_below(node, culprit);
        for (int a = 0; a < problem_.action_count(); ++a) {
          if (node.motion[static_cast<std::size_t>(a)] < 0 && node.effort[static_cast<std::size_t>(a)] == 0) {
            world.end[static_cast<std::size_t>(a)] = 0;  // (their next steps start new attempts)
          }
        }
      }
    }
    return 0.0;
  }

  // Every outcome of a new attempt of `action`, weighted by its probability.
  double draw(const Rule& rule, const Node& node, const World& world, int action) {
    const Action& a = problem_.action(action);
    const auto slot = static_cast<std::size_t>(action);
    double value = 0, listed = 0;
    for (int t = 1; t <= problem_.deadline(); ++t) {
      const double found = mass(a.planning, t);
      for (long x = 0; found > 0 && x <= problem_.deadline() + 1; ++x) {
        const double px = x <= problem_.deadline() ? a.execution.pmf(static_cast<Steps>(x))
                                                   : 1.0 - a.execution.cdf(problem_.deadline());
        if (px <= 0) continue;
        World drawn = world;
        drawn.end[slot] = t;
        drawn.execution[slot] = x;
        drawn.culprit[slot] = -1;
        value += found * px * run(rule, node, drawn);
      }
      for (const Culprit& culprit : a.culprits) {
        const double weight = mass(a.backtrack, t) * culprit.probability;
        if (weight <= 0) continue;
        World drawn = world;
        drawn.end[slot] = t;
        drawn.culprit[slot] = problem_.find_action(culprit.id);
        value += weight * run(rule, node, drawn);
      }
      listed += found + mass(a.backtrack, t);
    }
    if (listed < 1.0) {
      World drawn = world;
      drawn.end[slot] = -1;  // never ends within the deadline
      value += (1.0 - listed) * run(rule, node, drawn);
    }
    return value;
  }

  const Problem& problem_;
  std::map<Node, double> memo_;
};

}  // namespace ontime::testing
