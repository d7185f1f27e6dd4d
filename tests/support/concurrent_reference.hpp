#pragma once
// An independent, deliberately plain implementation of acting while planning (SPEC §10) and its
// optimal expectimax, written from the text of §10 and not from ConcurrentMdp: its own state
// (the executed path, every action's steps spent and execution time), every move of §10 at every
// state (the planner idling while work is left, starting any refined child of the executed path,
// waiting), no bound, no dropped skeleton, no shortcut to success: the episode ends only when the
// robot starts the last action of a skeleton, and fails at the deadline. The only states merged
// are those that differ in actions no skeleton through the executed path can use any more.
// Backtracking (SPEC §7 read with §10): an attempt that gives up un-refines the action it blames
// and every action below it, their effort too, but for what is executed; blaming an executed one
// also blocks the action that gave up for good.
//
// plan_first() values the plan-first policies of the same MDP (SPEC §2 and §8 read as a policy
// of §10: the robot never moves until a skeleton is refined in full, then runs the first one that
// fits from that step): its optimum must be OptimalSolver's. Exponential; small instances only.

#include <algorithm>
#include <map>
#include <vector>

#include "ontime/model/problem.hpp"

namespace ontime::testing {

class ConcurrentReference {
 public:
  explicit ConcurrentReference(const Problem& problem) : problem_(problem) {}

  // The optimum of SPEC §10.
  double optimum() { return solve(false); }
  // The best plan-first policy, valued in the same model.
  double plan_first() { return solve(true); }

 private:
  static constexpr long kUnrefined = -1;
  static constexpr long kExecuted = -2;  // executed or executing: its time is in robot_left
  static constexpr long kBlocked = -3;   // gave up blaming an executed action: never refined again

  struct Node {
    int time = 0;
    long robot_left = 0;
    std::vector<int> executed;    // the executed path, in order
    std::vector<int> spent;       // per action: steps on its current attempt
    std::vector<long> execution;  // per action: kUnrefined, kExecuted or its execution time
    auto operator<=>(const Node&) const = default;
  };

  double solve(bool plan_first) {
    plan_first_ = plan_first;
    memo_.clear();
    const auto actions = static_cast<std::size_t>(problem_.action_count());
    return value(Node{0, 0, {}, std::vector<int>(actions, 0), std::vector<long>(actions, kUnrefined)});
  }

  bool through_executed(const Node& node, int k) const {
    const auto path = problem_.skeleton(k);
    if (path.size() < node.executed.size()) return false;
    return std::equal(node.executed.begin(), node.executed.end(), path.begin());
  }

  double reward(int k, long finish) const {
    if (finish > problem_.deadline()) return 0.0;
    return problem_.has_rewards() ? problem_.reward_at(k, static_cast<Steps>(finish)) : 1.0;
  }

  double value(const Node& node) {
    if (const auto found = memo_.find(node); found != memo_.end()) return found->second;
    double best = 0.0;
    const int skeletons = problem_.skeleton_count();
    const std::size_t depth = node.executed.size();
    if (plan_first_) {
      // The first skeleton refined in full whose execution from now fits ends the episode.
      for (int k = 0; k < skeletons; ++k) {
        long finish = node.time;
        bool refined = true;
        for (const int action : problem_.skeleton(k)) {
          const long x = node.execution[static_cast<std::size_t>(action)];
          if (x == kUnrefined) refined = false;
          finish += std::max(x, 0L);
        }
        if (refined && finish <= problem_.deadline()) {
          memo_.emplace(node, reward(k, finish));
          return reward(k, finish);
        }
      }
    } else if (node.robot_left == 0) {
      // Starts: any refined child of the executed path, on a skeleton through it.
      for (int k = 0; k < skeletons; ++k) {
        if (!through_executed(node, k) || problem_.skeleton_length(k) <= static_cast<int>(depth)) continue;
        const int child = problem_.action_at(k, static_cast<int>(depth));
        const long x = node.execution[static_cast<std::size_t>(child)];
        if (x < 0) continue;
        double start_value = 0.0;
        int ending = -1;
        for (int m = 0; m < skeletons; ++m) {
          if (through_executed(node, m) && problem_.skeleton_length(m) == static_cast<int>(depth) + 1 &&
              problem_.action_at(m, static_cast<int>(depth)) == child) {
            ending = m;
          }
        }
        if (ending >= 0) {
          start_value = reward(ending, node.time + x);
        } else {
          Node next = node;
          next.executed.push_back(child);
          next.robot_left = x;
          forget_unusable(next);
          start_value = value(next);
        }
        best = std::max(best, start_value);
      }
    }
    if (node.time < problem_.deadline()) {
      // The planner idles (the robot executes on), or refines the next action of a skeleton through
      // the executed path; skeletons with the same next action share it.
      Node idle = node;
      ++idle.time;
      idle.robot_left = std::max(0L, node.robot_left - 1);
      best = std::max(best, value(idle));
      std::vector<int> tried;
      for (int k = 0; k < skeletons; ++k) {
        if (!through_executed(node, k)) continue;
        int next_action = -1;
        for (const int action : problem_.skeleton(k)) {
          const long x = node.execution[static_cast<std::size_t>(action)];
          if (x == kBlocked) break;
          if (x == kUnrefined) {
            next_action = action;
            break;
          }
        }
        if (next_action < 0 || std::find(tried.begin(), tried.end(), next_action) != tried.end()) continue;
        tried.push_back(next_action);
        best = std::max(best, refine_value(idle, next_action));
      }
    }
    memo_.emplace(node, best);
    return best;
  }

  // One step of effort on `action` from `after` (the step's time and robot already advanced).
  double refine_value(const Node& after, int action) {
    const auto slot = static_cast<std::size_t>(action);
    const Distribution& planning = problem_.action(action).planning;
    const Distribution& backtrack = problem_.action(action).backtrack;
    const Steps spent = after.spent[slot];
    double survival = planning.survival(spent);
    double back = 0.0;
    if (!problem_.culprits(action).empty()) {
      // An attempt ends by a motion or by giving up: it survives what neither took.
      survival = 1.0;
      for (Steps u = 1; u <= spent; ++u) survival -= planning.pmf(u) + backtrack.pmf(u);
      back = survival > 0 ? backtrack.pmf(spent + 1) / survival : 0.0;
    }
    const double hazard = survival > 0 ? planning.pmf(spent + 1) / survival : 0.0;
    double q = 0.0;
    if (hazard + back < 1.0) {
      Node missed = after;
      ++missed.spent[slot];
      q += (1.0 - hazard - back) * value(missed);
    }
    for (const Problem::CulpritIndex& culprit : problem_.culprits(action)) {
      if (back <= 0.0 || culprit.probability <= 0.0) continue;
      q += back * culprit.probability * value(given_up(after, action, culprit.action));
    }
    if (hazard > 0.0) {
      const Distribution& execution = problem_.action(action).execution;
      double in_time = 0.0;
      for (Steps x = 0; x <= problem_.deadline(); ++x) {
        const double mass = execution.pmf(x);
        if (mass <= 0) continue;
        in_time += mass;
        Node found = after;
        found.execution[slot] = x;
        found.spent[slot] = 0;
        q += hazard * mass * value(found);
      }
      if (1.0 - in_time > 1e-15) {
        // Too slow or never: no skeleton through it can finish; valued all the same.
        Node found = after;
        found.execution[slot] = problem_.deadline() + 1L;
        found.spent[slot] = 0;
        q += hazard * (1.0 - in_time) * value(found);
      }
    }
    return q;
  }

  // The attempt on `action` gave up blaming `culprit` (SPEC §7, §10).
  Node given_up(const Node& after, int action, int culprit) const {
    Node next = after;
    // The culprit and every action below it (whose paths go through it) start again, but for what
    // is executed (its motion cannot be undone) and what is blocked (what blocked it is executed).
    const int at = problem_.position(culprit);
    for (int b = 0; b < problem_.action_count(); ++b) {
      const auto slot = static_cast<std::size_t>(b);
      const auto path = problem_.skeleton(problem_.members(b).front());
      if (static_cast<int>(path.size()) <= at || path[static_cast<std::size_t>(at)] != culprit) continue;
      if (problem_.position(b) < at || next.execution[slot] == kBlocked || next.execution[slot] == kExecuted) continue;
      next.execution[slot] = kUnrefined;
      next.spent[slot] = 0;
    }
    // An executed culprit cannot be refined again: the action that gave up never will be.
    if (std::find(after.executed.begin(), after.executed.end(), culprit) != after.executed.end()) {
      next.execution[static_cast<std::size_t>(action)] = kBlocked;
    }
    return next;
  }

  // Actions on no skeleton through the executed path can never be refined or executed again, and
  // the executed ones' times are in robot_left: their fields are set to fixed values.
  void forget_unusable(Node& node) const {
    for (int a = 0; a < problem_.action_count(); ++a) {
      const auto slot = static_cast<std::size_t>(a);
      bool usable = false;
      for (int k = 0; k < problem_.skeleton_count(); ++k) {
        if (!through_executed(node, k)) continue;
        const auto path = problem_.skeleton(k);
        const auto at = std::find(path.begin(), path.end(), a);
        if (at != path.end() && static_cast<std::size_t>(at - path.begin()) >= node.executed.size()) usable = true;
      }
      if (std::find(node.executed.begin(), node.executed.end(), a) != node.executed.end()) {
        node.execution[slot] = kExecuted;
        node.spent[slot] = 0;
      } else if (!usable) {
        node.execution[slot] = kUnrefined;
        node.spent[slot] = 0;
      }
    }
  }

  const Problem& problem_;
  bool plan_first_ = false;
  std::map<Node, double> memo_;
};

}  // namespace ontime::testing
