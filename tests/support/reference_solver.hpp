#pragma once
// An independent, deliberately plain implementation of SPEC §2 and optimal expectimax, used
// to check the library's solver: its own state, its own transitions from the distributions'
// pmf and survival, every legal choice (idle ones included), no pruning, no early failure.
// It also gives the value of a stationary rule written on its own state, to check exact
// evaluation of an allocator against a second implementation of that allocator.
// With rewards (SPEC §8) its values are expected rewards. Exponential; for small instances only.

#include <algorithm>
#include <functional>
#include <map>
#include <vector>

#include "ontime/model/problem.hpp"

namespace ontime::testing {

class ReferenceSolver {
 public:
  // The state of SPEC §2, kept plainly (execution times are not saturated).
  struct Node {
    int time;
    std::vector<int> refined, spent;
    std::vector<long> execution;
    auto operator<=>(const Node&) const = default;
  };
  // A stationary allocator written on this state: the skeleton to spend the step on.
  using Rule = std::function<int(const Node&)>;

  explicit ReferenceSolver(const Problem& problem) : problem_(problem) {}

  double optimum() { return solve({}); }

  // The success probability of choosing by `rule` in every state.
  double value_of(Rule rule) { return solve(std::move(rule)); }

 private:
  static constexpr long kTooSlow = 1'000'000;

  double solve(Rule rule) {
    rule_ = std::move(rule);
    memo_.clear();
    const std::size_t k = static_cast<std::size_t>(problem_.skeleton_count());
    return value(Node{0, std::vector<int>(k, 0), std::vector<int>(k, 0), std::vector<long>(k, 0)});
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

  // The success probability of spending the step on skeleton k, then continuing as value() does.
  double choice_value(const Node& node, int k) {
    const int count = problem_.skeleton_count();
    const auto slot = static_cast<std::size_t>(k);
    Node next = node;
    ++next.time;
    if (node.refined[slot] == problem_.skeleton_length(k)) return value(next);  // idle step
    const int action = problem_.action_at(k, node.refined[slot]);
    std::vector<std::size_t> sharing;
    for (int m = 0; m < count; ++m) {
      const auto other = static_cast<std::size_t>(m);
      if (node.refined[other] < problem_.skeleton_length(m) && problem_.action_at(m, node.refined[other]) == action) {
        sharing.push_back(other);
      }
    }
    const Distribution& planning = problem_.action(action).planning;
    const double survival = planning.survival(node.spent[slot]);
    const double hazard = survival > 0 ? planning.pmf(node.spent[slot] + 1) / survival : 0.0;
    Node missed = next;
    for (const std::size_t m : sharing) ++missed.spent[m];
    double q = (1.0 - hazard) * value(missed);
    const Distribution& execution = problem_.action(action).execution;
    std::vector<std::pair<long, double>> durations;
    for (Steps x = 0; x <= std::max<Steps>(execution.max_step() == kNever ? 0 : execution.max_step(), 0); ++x) {
      if (execution.pmf(x) > 0) durations.emplace_back(x, execution.pmf(x));
    }
    if (execution.never() > 0) durations.emplace_back(kTooSlow, execution.never());
    for (const auto& [duration, probability] : durations) {
      Node found = next;
      // The best reward of a skeleton completed in time (SPEC §8: value - per_step * finish), or
      // none.
      double reward = -1.0;
      for (const std::size_t m : sharing) {
        ++found.refined[m];
        found.spent[m] = 0;
        found.execution[m] = std::min(kTooSlow, found.execution[m] + duration);
        const long finish = found.time + found.execution[m];
        if (found.refined[m] == problem_.skeleton_length(static_cast<int>(m)) && finish <= problem_.deadline()) {
          const SkeletonReward& worth = problem_.rewards()[m];
          reward = std::max(reward, worth.value - worth.per_step * static_cast<double>(finish));
        }
      }
      q += hazard * probability * (reward >= 0.0 ? reward : value(found));
    }
    return q;
  }

  const Problem& problem_;
  Rule rule_;
  std::map<Node, double> memo_;
};

}  // namespace ontime::testing
