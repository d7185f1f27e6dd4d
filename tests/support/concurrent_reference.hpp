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
// Exogenous chains and expiry (SPEC §9 read with §10): every step moves each chain by its own row
// (they are independent), a start moves nothing; an execution that depends on a chain is drawn
// from its row for the chain's state when the action starts; an action that expires starts only up
// to its step `after` and in no blocking state of its chain.
//
// plan_first() values the plan-first policies of the same MDP (SPEC §2 and §8 read as a policy
// of §10: the robot never moves until a skeleton is refined in full, then runs the first one that
// fits from that step): its optimum must be OptimalSolver's; not with chains or expiry.
// devoted(k) values one policy of the same MDP, the devoted eager one of skeleton k: the planner
// refines k alone, the robot starts k's next action as soon as it is refined, the robot is idle and
// the action may start, and the planner idles once k has nothing left to refine (or the next
// action is blocked for good). The episode may still end through a skeleton that is a prefix of k.
// Exponential; small instances only.

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
  // The devoted eager policy of skeleton k (above), valued in the same model.
  double devoted(int k) {
    devoted_ = k;
    const double value = solve(false);
    devoted_ = -1;
    return value;
  }

 private:
  static constexpr long kUnrefined = -1;
  static constexpr long kExecuted = -2;      // executed or executing: its time is in robot_left
  static constexpr long kBlocked = -3;       // gave up blaming an executed action: never refined again
  static constexpr long kDrawnAtStart = -4;  // refined; its execution is drawn from a chain at its start

  struct Node {
    int time = 0;
    long robot_left = 0;
    std::vector<int> executed;    // the executed path, in order
    std::vector<int> spent;       // per action: steps on its current attempt
    std::vector<long> execution;  // per action: kUnrefined, kExecuted, kBlocked, kDrawnAtStart or its time
    std::vector<int> chains;      // per chain: its state
    auto operator<=>(const Node&) const = default;
  };

  double solve(bool plan_first) {
    plan_first_ = plan_first;
    memo_.clear();
    const auto actions = static_cast<std::size_t>(problem_.action_count());
    std::vector<int> chains;
    for (const ExogenousChain& chain : problem_.chains()) chains.push_back(chain.start);
    return value(Node{0, 0, {}, std::vector<int>(actions, 0), std::vector<long>(actions, kUnrefined), chains});
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
    if (devoted_ >= 0) {
      const double devoted = devoted_value(node);
      memo_.emplace(node, devoted);
      return devoted;
    }
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
        if ((x < 0 && x != kDrawnAtStart) || !may_start(node, child)) continue;
        best = std::max(best, start_value(node, child));
      }
    }
    if (node.time < problem_.deadline()) {
      // The planner idles (the robot executes on), or refines the next action of a skeleton through
      // the executed path; skeletons with the same next action share it.
      Node idle = node;
      ++idle.time;
      idle.robot_left = std::max(0L, node.robot_left - 1);
      best = std::max(best, after_step(idle));
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

  // The value of starting refined `child` of the executed path now (it may start).
  double start_value(const Node& node, int child) {
    const int skeletons = problem_.skeleton_count();
    const std::size_t depth = node.executed.size();
    const long x = node.execution[static_cast<std::size_t>(child)];
    int ending = -1;
    for (int m = 0; m < skeletons; ++m) {
      if (through_executed(node, m) && problem_.skeleton_length(m) == static_cast<int>(depth) + 1 &&
          problem_.action_at(m, static_cast<int>(depth)) == child) {
        ending = m;
      }
    }
    const auto start_with = [&](long steps) {
      if (ending >= 0) return reward(ending, node.time + steps);
      Node next = node;
      next.executed.push_back(child);
      next.robot_left = steps;
      forget_unusable(next);
      return value(next);
    };
    double total = 0.0;
    if (x != kDrawnAtStart) {
      total = start_with(x);
    } else {
      // Drawn now, from the row of the chain's state.
      const int chain = problem_.execution_chain(child);
      const Distribution& drawn =
          problem_.action(child)
              .execution_by_state[static_cast<std::size_t>(node.chains[static_cast<std::size_t>(chain)])];
      double in_time = 0.0;
      for (Steps steps = 0; steps <= problem_.deadline(); ++steps) {
        if (drawn.pmf(steps) <= 0) continue;
        in_time += drawn.pmf(steps);
        total += drawn.pmf(steps) * start_with(steps);
      }
      if (1.0 - in_time > 1e-15) total += (1.0 - in_time) * start_with(problem_.deadline() + 1L);
    }
    return total;
  }

  // The devoted policy's move (devoted()) in `node`, and its value.
  double devoted_value(const Node& node) {
    const int k = devoted_;
    if (!through_executed(node, k)) return 0.0;
    const std::size_t depth = node.executed.size();
    if (node.robot_left == 0 && static_cast<int>(depth) < problem_.skeleton_length(k)) {
      const int child = problem_.action_at(k, static_cast<int>(depth));
      const long x = node.execution[static_cast<std::size_t>(child)];
      if ((x >= 0 || x == kDrawnAtStart) && may_start(node, child)) return start_value(node, child);
    }
    if (node.time >= problem_.deadline()) return 0.0;
    Node idle = node;
    ++idle.time;
    idle.robot_left = std::max(0L, node.robot_left - 1);
    for (const int action : problem_.skeleton(k)) {
      const long x = node.execution[static_cast<std::size_t>(action)];
      if (x == kBlocked) break;
      if (x == kUnrefined) return refine_value(idle, action);
    }
    return after_step(idle);
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
      q += (1.0 - hazard - back) * after_step(missed);
    }
    for (const Problem::CulpritIndex& culprit : problem_.culprits(action)) {
      if (back <= 0.0 || culprit.probability <= 0.0) continue;
      q += back * culprit.probability * after_step(given_up(after, action, culprit.action));
    }
    if (hazard > 0.0 && problem_.execution_chain(action) >= 0) {
      Node found = after;
      found.execution[slot] = kDrawnAtStart;
      found.spent[slot] = 0;
      q += hazard * after_step(found);
    } else if (hazard > 0.0) {
      const Distribution& execution = problem_.action(action).execution;
      double in_time = 0.0;
      for (Steps x = 0; x <= problem_.deadline(); ++x) {
        const double mass = execution.pmf(x);
        if (mass <= 0) continue;
        in_time += mass;
        Node found = after;
        found.execution[slot] = x;
        found.spent[slot] = 0;
        q += hazard * mass * after_step(found);
      }
      if (1.0 - in_time > 1e-15) {
        // Too slow or never: no skeleton through it can finish; valued all the same.
        Node found = after;
        found.execution[slot] = problem_.deadline() + 1L;
        found.spent[slot] = 0;
        q += hazard * (1.0 - in_time) * after_step(found);
      }
    }
    return q;
  }

  // The value of `node`, reached by a step: each chain moves by its row, independently.
  double after_step(const Node& node) {
    double total = 0.0;
    Node moved = node;
    const auto move = [&](const auto& self, std::size_t c, double probability) -> void {
      if (c == problem_.chains().size()) {
        total += probability * value(moved);
        return;
      }
      const std::vector<double>& row = problem_.chains()[c].transitions[static_cast<std::size_t>(node.chains[c])];
      for (std::size_t to = 0; to < row.size(); ++to) {
        if (row[to] <= 0) continue;
        moved.chains[c] = static_cast<int>(to);
        self(self, c + 1, probability * row[to]);
      }
    };
    move(move, 0, 1.0);
    return total;
  }

  // SPEC §9's expiry: `action` may start now (not past its step `after`, not blocked).
  bool may_start(const Node& node, int action) const {
    const Action& model = problem_.action(action);
    if (model.start_by != kNever && node.time > model.start_by) return false;
    const int chain = problem_.blocking_chain(action);
    return chain < 0 || !problem_.blocks(action, node.chains[static_cast<std::size_t>(chain)]);
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
  int devoted_ = -1;  // the skeleton of devoted(), -1 otherwise
  std::map<Node, double> memo_;
};

}  // namespace ontime::testing
