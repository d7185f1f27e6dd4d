#pragma once
// An independent, deliberately plain implementation of SPEC §9 (exogenous chains and actions that
// expire, with §8's rewards and §7's backtracking) and of optimal expectimax over it, to check the
// library's solvers: its own state (every refined action's drawn execution kept in order, the
// chains' states), its own transitions, every legal choice, no pruning; the plan's execution
// followed step by step along every path of the chains. A backtrack to culprit c cuts every
// skeleton through c back to c's position: its drawn executions from there on are forgotten, so
// its execution before c is what is left. Exponential; for small instances only.

#include <algorithm>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "ontime/model/instance_io.hpp"
#include "ontime/model/problem.hpp"

namespace ontime::testing {

// A queue and one wait (deadline 4) for cases valued by hand: the wait is refined in step 1 and
// starts at once; it takes 1 step if the queue is short then (probability 0.7), else 5, past the
// deadline. `expires` adds to the action's fields (e.g. `, "expires": {"after": 0}`).
inline Problem queue_wait_instance(const std::string& expires) {
  return parse_problem(R"({"deadline": 4,
      "chains": {"queue": {"states": ["short", "long"], "start": "short", "transitions": [[0.7, 0.3], [0.4, 0.6]]}},
      "actions": {"wait": {"planning": {"pmf": {"1": 1.0}},
          "execution": {"chain": "queue", "by_state": {"short": {"pmf": {"1": 1.0}}, "long": {"pmf": {"5": 1.0}}}})" +
                           expires + R"(}}, "skeletons": [["wait"]]})",
                       "wait.json");
}

// go then through, each found in 1 step and run in 1; through cannot start while the door is
// locked, locked at 0 and opening with probability 1/2 per step for good; deadline 6. Plan-first
// is worth 1 - 1/8 (through starts at 3), acting while planning 1 - 1/32 (the robot waits at the
// door and starts through at the first open step up to 5).
inline Problem door_opening_at_random() {
  return parse_problem(R"({"deadline": 6,
    "chains": {"door": {"states": ["open", "locked"], "start": "locked", "transitions": [[1, 0], [0.5, 0.5]]}},
    "actions": {"go": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"1": 1}}},
                "through": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"1": 1}},
                            "expires": {"chain": "door", "states": ["locked"]}}},
    "skeletons": [["go", "through"]]})",
                       "door");
}

// A door open at even steps only, and a plan through it found in one step: entering as soon as the
// motion is found (step 1) fails; a step spent elsewhere first (on a plan that cannot succeed)
// waits for the door and succeeds.
inline Problem door_open_at_even_steps() {
  return parse_problem(R"({"deadline": 6,
      "chains": {"door": {"states": ["open", "locked"], "start": "open", "transitions": [[0, 1], [1, 0]]}},
      "actions": {"enter": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"1": 1.0}},
                            "expires": {"chain": "door", "states": ["locked"]}},
                  "other": {"planning": {"pmf": {}}, "execution": {"pmf": {"1": 1.0}}}},
      "skeletons": [["enter"], ["other"]]})",
                       "door.json");
}

// With backtracking (SPEC §7) too: z (found in step 1, executes 2 steps) then a (found in step 1, executes 2, cannot
// start while the door is locked), then b, whose attempts give up after one step and blame a, or find a motion after
// two, half the time each. The door alternates open and locked every step.
inline Problem door_and_regrasp() {
  return parse_problem(R"({"deadline": 20,
      "chains": {"door": {"states": ["open", "locked"], "start": "open", "transitions": [[0, 1], [1, 0]]}},
      "actions": {
        "z": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"2": 1.0}}},
        "a": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"2": 1.0}},
              "expires": {"chain": "door", "states": ["locked"]}},
        "b": {"planning": {"pmf": {"2": 0.5}}, "execution": {"pmf": {"1": 1.0}},
              "backtrack": {"pmf": {"1": 0.5}}, "culprits": {"a": 1.0}}},
      "skeletons": [["z", "a", "b"]]})",
                       "door-and-regrasp.json");
}

class ChainReferenceSolver {
 public:
  struct Node {
    int time;
    std::vector<int> refined, spent;
    // Per skeleton, the execution drawn for each refined action in order; kAtStart for an action
    // whose execution depends on a chain (drawn when it starts).
    std::vector<std::vector<long>> executions;
    std::vector<int> chains;  // each chain's state
    auto operator<=>(const Node&) const = default;
  };
  using Rule = std::function<int(const Node&)>;
  static constexpr long kAtStart = -1;
  static constexpr long kTooSlow = 1'000'000;

  explicit ChainReferenceSolver(const Problem& problem) : problem_(problem) {}

  // The chains' joint state of a node, numbered as the library numbers it (the first chain's
  // state varies fastest).
  int joint(const Node& node) const {
    int value = 0;
    int stride = 1;
    for (std::size_t c = 0; c < node.chains.size(); ++c) {
      value += node.chains[c] * stride;
      stride *= problem_.chains()[c].state_count();
    }
    return value;
  }

  double optimum() { return solve({}); }
  double value_of(Rule rule) { return solve(std::move(rule)); }
  // The value of following `rule` from `node` on.
  double value_from(const Node& node, Rule rule) {
    rule_ = std::move(rule);
    memo_.clear();
    return value(node);
  }

  // The expected reward of executing skeleton m from step `start` with the chains in `chains`,
  // its refined actions' executions `executions` (kAtStart: drawn when the action starts).
  double execution_value(int m, int start, const std::vector<long>& executions, const std::vector<int>& chains) {
    return execute(m, 0, start, executions, chains);
  }

 private:
  double solve(Rule rule) {
    rule_ = std::move(rule);
    memo_.clear();
    const auto k = static_cast<std::size_t>(problem_.skeleton_count());
    std::vector<int> chains;
    for (const ExogenousChain& chain : problem_.chains()) chains.push_back(chain.start);
    return value(Node{0, std::vector<int>(k, 0), std::vector<int>(k, 0), std::vector<std::vector<long>>(k), chains});
  }

  // Calls visit(probability, next) for every joint next state of the chains.
  void for_each_chain_step(const std::vector<int>& chains,
                           const std::function<void(double, const std::vector<int>&)>& visit, std::size_t c = 0,
                           double probability = 1.0, std::vector<int> next = {}) {
    if (c == chains.size()) {
      visit(probability, next);
      return;
    }
    const ExogenousChain& chain = problem_.chains()[c];
    const auto& row = chain.transitions[static_cast<std::size_t>(chains[c])];
    for (std::size_t s = 0; s < row.size(); ++s) {
      if (row[s] <= 0) continue;
      std::vector<int> more = next;
      more.push_back(static_cast<int>(s));
      for_each_chain_step(chains, visit, c + 1, probability * row[s], more);
    }
  }

  // Action `position` of skeleton m starts at `time` with the chains in `chains`.
  double execute(int m, std::size_t position, long time, const std::vector<long>& executions,
                 const std::vector<int>& chains) {
    const auto path = problem_.skeleton(m);
    if (time > problem_.deadline()) return 0.0;
    if (position == path.size()) {
      const SkeletonReward& reward = problem_.rewards()[static_cast<std::size_t>(m)];
      return reward.value - reward.per_step * static_cast<double>(time);
    }
    const Action& action = problem_.action(path[position]);
    if (action.start_by != kNever && time > action.start_by) return 0.0;
    if (!action.blocking_chain.empty()) {
      for (std::size_t c = 0; c < problem_.chains().size(); ++c) {
        const ExogenousChain& chain = problem_.chains()[c];
        if (chain.name != action.blocking_chain) continue;
        const std::string& state = chain.states[static_cast<std::size_t>(chains[c])];
        if (std::find(action.blocking_states.begin(), action.blocking_states.end(), state) !=
            action.blocking_states.end()) {
          return 0.0;
        }
      }
    }
    std::vector<std::pair<long, double>> durations;
    if (executions[position] == kAtStart) {
      for (std::size_t c = 0; c < problem_.chains().size(); ++c) {
        if (problem_.chains()[c].name != action.execution_chain) continue;
        const Distribution& by_state = action.execution_by_state[static_cast<std::size_t>(chains[c])];
        for (Steps x = 0; by_state.max_step() != kNever && x <= by_state.max_step(); ++x) {
          if (by_state.pmf(x) > 0) durations.emplace_back(x, by_state.pmf(x));
        }
      }
    } else {
      durations.emplace_back(executions[position], 1.0);
    }
    double total = 0;
    for (const auto& [duration, probability] : durations) {
      total += probability * after(m, position + 1, time, duration, executions, chains);
    }
    return total;
  }

  // `left` more steps of the current action, the chains moving one step at a time, then the next.
  double after(int m, std::size_t position, long time, long left, const std::vector<long>& executions,
               const std::vector<int>& chains) {
    if (time > problem_.deadline() || left >= kTooSlow) return 0.0;
    if (left == 0) return execute(m, position, time, executions, chains);
    double total = 0;
    for_each_chain_step(chains, [&](double probability, const std::vector<int>& next) {
      total += probability * after(m, position, time + 1, left - 1, executions, next);
    });
    return total;
  }

  double value(const Node& node) {
    if (node.time >= problem_.deadline()) return 0.0;
    if (const auto found = memo_.find(node); found != memo_.end()) return found->second;
    double best = 0.0;
    if (rule_) {
      best = choice_value(node, rule_(node));
    } else {
      for (int k = 0; k < problem_.skeleton_count(); ++k) best = std::max(best, choice_value(node, k));
    }
    memo_.emplace(node, best);
    return best;
  }

  // Spending the step on skeleton k: what refinement reveals, the chains' step, then success
  // (the plan's execution value) or value() of the next state.
  double choice_value(const Node& node, int k) {
    const auto slot = static_cast<std::size_t>(k);
    double total = 0;
    const auto settle = [&](double probability, Node next) {
      for_each_chain_step(node.chains, [&](double moved, const std::vector<int>& chains) {
        Node after_step = next;
        after_step.time = node.time + 1;
        after_step.chains = chains;
        // A plan completed in this step whose drawn executions fit is executed: the episode ends.
        double executed = -1.0;
        for (int m = 0; m < problem_.skeleton_count(); ++m) {
          const auto index = static_cast<std::size_t>(m);
          if (after_step.refined[index] != problem_.skeleton_length(m) ||
              node.refined[index] == problem_.skeleton_length(m)) {
            continue;
          }
          long fixed = 0;
          for (const long x : after_step.executions[index]) fixed += x == kAtStart ? 0 : x;
          if (after_step.time + fixed > problem_.deadline()) continue;
          executed = std::max(executed, execution_value(m, after_step.time, after_step.executions[index], chains));
        }
        total += probability * moved * (executed >= 0.0 ? executed : value(after_step));
      });
    };
    if (node.refined[slot] == problem_.skeleton_length(k)) {  // an idle step
      settle(1.0, node);
      return total;
    }
    const int action = problem_.action_at(k, node.refined[slot]);
    std::vector<std::size_t> sharing;
    for (int m = 0; m < problem_.skeleton_count(); ++m) {
      const auto other = static_cast<std::size_t>(m);
      if (node.refined[other] < problem_.skeleton_length(m) && problem_.action_at(m, node.refined[other]) == action) {
        sharing.push_back(other);
      }
    }
    const Action& model = problem_.action(action);
    const int spent = node.spent[slot];
    double hazard = 0.0;
    double back = 0.0;
    if (model.backtrack.never() >= 1.0) {
      const double survival = model.planning.survival(spent);
      hazard = survival > 0 ? model.planning.pmf(spent + 1) / survival : 0.0;
    } else {
      // The attempt ends with a motion or a give-up; P(neither in `spent` steps), summed plainly.
      double alive = 1.0;
      for (int t = 1; t <= spent; ++t) alive -= model.planning.pmf(t) + model.backtrack.pmf(t);
      hazard = alive > 0 ? model.planning.pmf(spent + 1) / alive : 0.0;
      back = alive > 0 ? model.backtrack.pmf(spent + 1) / alive : 0.0;
    }
    Node missed = node;
    for (const std::size_t m : sharing) ++missed.spent[m];
    settle(1.0 - hazard - back, missed);
    for (const Culprit& culprit : model.culprits) {
      if (back <= 0 || culprit.probability <= 0) continue;
      const int blamed = problem_.find_action(culprit.id);
      const auto position = static_cast<std::size_t>(problem_.position(blamed));
      Node undone = node;
      for (int m = 0; m < problem_.skeleton_count(); ++m) {
        const auto index = static_cast<std::size_t>(m);
        const auto path = problem_.skeleton(m);
        if (path.size() <= position || path[position] != blamed ||
            undone.refined[index] <= static_cast<int>(position)) {
          continue;
        }
        undone.refined[index] = static_cast<int>(position);
        undone.spent[index] = 0;
        undone.executions[index].resize(position);
      }
      settle(back * culprit.probability, undone);
    }
    std::vector<std::pair<long, double>> drawn;
    if (!model.execution_chain.empty()) {
      drawn.emplace_back(kAtStart, 1.0);
    } else {
      for (Steps x = 0; model.execution.max_step() != kNever && x <= model.execution.max_step(); ++x) {
        if (model.execution.pmf(x) > 0) drawn.emplace_back(x, model.execution.pmf(x));
      }
      if (model.execution.never() > 0) drawn.emplace_back(kTooSlow, model.execution.never());
    }
    for (const auto& [execution, probability] : drawn) {
      Node found = node;
      for (const std::size_t m : sharing) {
        ++found.refined[m];
        found.spent[m] = 0;
        found.executions[m].push_back(execution);
      }
      settle(hazard * probability, found);
    }
    return total;
  }

  const Problem& problem_;
  Rule rule_;
  std::map<Node, double> memo_;
};

}  // namespace ontime::testing
