#pragma once
// An independent, deliberately plain implementation of SPEC §2 and optimal expectimax, used
// to check the library's solver: its own state, its own transitions from the distributions'
// pmf and survival, every legal choice (idle ones included), no pruning, no early failure.
// Exponential; for small instances only.

#include <algorithm>
#include <map>
#include <vector>

#include "ontime/problem.hpp"

namespace ontime::testing {

class ReferenceSolver {
 public:
  explicit ReferenceSolver(const Problem& problem) : problem_(problem) {}

  double optimum() {
    const std::size_t k = static_cast<std::size_t>(problem_.skeleton_count());
    return value(Node{0, std::vector<int>(k, 0), std::vector<int>(k, 0), std::vector<long>(k, 0)});
  }

 private:
  struct Node {
    int time;
    std::vector<int> refined, spent;
    std::vector<long> execution;
    auto operator<=>(const Node&) const = default;
  };
  static constexpr long kTooSlow = 1'000'000;

  double value(const Node& node) {
    if (node.time >= problem_.deadline()) return 0.0;
    if (const auto found = memo_.find(node); found != memo_.end()) return found->second;
    double best = 0.0;
    const int count = problem_.skeleton_count();
    for (int k = 0; k < count; ++k) {
      const auto slot = static_cast<std::size_t>(k);
      Node next = node;
      ++next.time;
      if (node.refined[slot] == problem_.skeleton_length(k)) {
        best = std::max(best, value(next));  // idle step
        continue;
      }
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
        bool success = false;
        for (const std::size_t m : sharing) {
          ++found.refined[m];
          found.spent[m] = 0;
          found.execution[m] = std::min(kTooSlow, found.execution[m] + duration);
          success = success || (found.refined[m] == problem_.skeleton_length(static_cast<int>(m)) &&
                                found.time + found.execution[m] <= problem_.deadline());
        }
        q += hazard * probability * (success ? 1.0 : value(found));
      }
      best = std::max(best, q);
    }
    memo_.emplace(node, best);
    return best;
  }

  const Problem& problem_;
  std::map<Node, double> memo_;
};

}  // namespace ontime::testing
