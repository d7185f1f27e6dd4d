#include "ontime/solve/value_bounds.hpp"

#include <algorithm>
#include <array>
#include <span>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

// Fills a D x D block T[s][b - 1] (spent s in [0, D), budget b in [1, D]) of the recursion
//   T[s][b] = h(s) * found[b - 1] + (1 - h(s)) * T[s + 1][b - 1],
// with T = 0 once s reaches D (the hazard is 0 from there on) or b reaches 0. found[m] is the
// value of finding the motion with m steps of budget left after the finding step.
//
// With backtracking (SPEC §7), a step also gives up with probability g(s): the recursion is
//   T[s][b] = h(s) * found[b - 1] + [win] g(s) + (1 - h(s) - g(s)) * T[s + 1][b - 1],
// where a give-up is worth nothing to the commit bound, and everything to the relaxation of the
// upper bound (`win` given), whose T[s][0] is then win[s] rather than 0 (a give-up needs no
// budget).
void fill_block(const Mdp& mdp, int action, const std::vector<double>& found, double* block, const double* win) {
  const auto deadline = static_cast<std::size_t>(mdp.deadline());
  for (std::size_t s = deadline; s-- > 0;) {
    const double hazard = mdp.hazard(action, static_cast<Steps>(s));
    const double back = mdp.backtrack_hazard(action, static_cast<Steps>(s));
    const double gives_up = win != nullptr ? back : 0.0;
    double* row = block + s * deadline;
    const double* next = s + 1 < deadline ? block + (s + 1) * deadline : nullptr;
    for (std::size_t b = 1; b <= deadline; ++b) {
      double missed = next != nullptr && b > 1 ? next[b - 2] : 0.0;
      if (b == 1 && win != nullptr) missed = win[s + 1];
      // A probability: rounding must not carry it above 1.
      row[b - 1] = back == 0.0 ? std::min(1.0, hazard * found[b - 1] + (1.0 - hazard) * missed)
                               : std::min(1.0, hazard * found[b - 1] + gives_up + (1.0 - hazard - back) * missed);
    }
  }
}

// found[m] = sum over execution times x <= m of P(x) * after[m - x], for m in [0, D): the
// value of finding the motion of `action` given the value after[r] of having r >= 0 steps
// of budget left once it is refined (slower executions leave a negative budget: value
// `too_slow`, 0 but for the upper bound under backtracking, where the actions below may still
// give up).
// With chains (SPEC §9) an execution that depends on a chain counts 0 steps here, the relaxation
// of the upper bound (`action.execution` is not its distribution then).
std::vector<double> convolve_execution(const Action& action, const std::vector<double>& after, double too_slow) {
  const std::size_t size = after.size();
  std::vector<double> found(size, 0.0);
  static constexpr std::array<double, 1> kNoSteps{1.0};
  const std::span<const double> masses =
      action.execution_chain.empty() ? action.execution.masses() : std::span<const double>(kNoSteps);
  for (std::size_t x = 0; x < std::min(size, masses.size()); ++x) {
    if (masses[x] <= 0.0) continue;
    for (std::size_t m = x; m < size; ++m) found[m] += masses[x] * after[m - x];
  }
  if (too_slow > 0.0) {
    double fits = 0.0;  // P(x <= m)
    for (std::size_t m = 0; m < size; ++m) {
      if (m < masses.size()) fits += masses[m];
      found[m] = std::min(1.0, found[m] + std::max(0.0, 1.0 - fits) * too_slow);
    }
  }
  return found;
}

}  // namespace

ValueBounds::ValueBounds(const Mdp& mdp, std::size_t max_table_entries)
    : mdp_(&mdp), skeleton_count_(mdp.skeleton_count()), deadline_(mdp.deadline()) {
  const Problem& problem = mdp.problem();
  const auto deadline = static_cast<std::size_t>(deadline_);
  const std::size_t block = deadline * deadline;
  max_reward_ = problem.max_reward();
  // Committing to k may end in the success of a skeleton whose path is a prefix of k's (it
  // completes on the way): the least reward at the deadline over those and k.
  for (int k = 0; k < skeleton_count_; ++k) {
    double floor = problem.reward_at(k, deadline_);
    for (int m = 0; m < skeleton_count_; ++m) {
      const int length = problem.skeleton_length(m);
      if (length < problem.skeleton_length(k) && problem.action_at(k, length - 1) == problem.action_at(m, length - 1)) {
        floor = std::min(floor, problem.reward_at(m, deadline_));
      }
    }
    // With chains or expiry (SPEC §9) the commit tables, made from the static distributions, do not
    // value the chains: no commit value is claimed (lower() is 0, sound and vacuous).
    reward_floor_.push_back(mdp.is_timed() ? 0.0 : floor);
  }

  // The nodes of the prefix tree (actions some skeleton uses), deepest first, so that
  // children come before their parents.
  std::vector<int> nodes;
  for (int a = 0; a < problem.action_count(); ++a) {
    if (problem.position(a) >= 0) nodes.push_back(a);
  }
  std::stable_sort(nodes.begin(), nodes.end(),
                   [&problem](int x, int y) { return problem.position(x) > problem.position(y); });
  std::size_t positions = 0;
  for (int k = 0; k < skeleton_count_; ++k) positions += static_cast<std::size_t>(problem.skeleton_length(k));

  const std::size_t entries = (nodes.size() + positions) * block;
  if (entries > max_table_entries) {
    throw ResourceLimitError("value bounds: the tables would hold " + std::to_string(entries) + " doubles (" +
                             std::to_string((entries * sizeof(double)) >> 20) + " MiB), above the cap of " +
                             std::to_string(max_table_entries) + " (the max_table_entries argument)");
  }

  // Upper bound: G(n, s, b) = P(some completion below n fits b | PT_n > s), one block per node.
  reach_.assign(nodes.size() * block, 0.0);
  std::vector<std::size_t> node_block(static_cast<std::size_t>(problem.action_count()), kNoTable);
  std::vector<std::vector<int>> children(static_cast<std::size_t>(problem.action_count()));
  for (const int n : nodes) {
    if (problem.parent(n) >= 0) children[static_cast<std::size_t>(problem.parent(n))].push_back(n);
  }
  // With backtracking, the relaxation counts a give-up as a success (docs/theory.md): W(n, s) =
  // P(some action of n's subtree gives up | PT_n > s), whatever the budget, is its value where
  // the budget is spent; (D + 1) doubles per node, W(n, D) = 0.
  const bool backtracking = mdp.has_backtracking();
  const std::size_t win_size = deadline + 1;
  if (backtracking) win_.assign(nodes.size() * win_size, 0.0);
  std::vector<double> after(deadline);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const int n = nodes[i];
    const auto slot = static_cast<std::size_t>(n);
    node_block[slot] = i * block;
    // Below n, once refined: P(some child's subtree gives up), whatever the budget.
    double below_gives_up = 0.0;
    if (backtracking) {
      double none = 1.0;
      for (const int child : children[slot])
        none *= 1.0 - win_[node_block[static_cast<std::size_t>(child)] / block * win_size];
      below_gives_up = 1.0 - none;
      double* win = win_.data() + i * win_size;
      for (std::size_t s = deadline; s-- > 0;) {
        const double hazard = mdp.hazard(n, static_cast<Steps>(s));
        const double back = mdp.backtrack_hazard(n, static_cast<Steps>(s));
        win[s] = std::min(1.0, back + hazard * below_gives_up + (1.0 - hazard - back) * win[s + 1]);
      }
    }
    // H(n, r) for r in [0, D): 1 when n completes a skeleton, else P(some child's subtree fits r).
    for (std::size_t r = 0; r < deadline; ++r) {
      if (problem.completes_a_skeleton(n)) {
        after[r] = 1.0;
        continue;
      }
      double all_fail = 1.0;
      for (const int child : children[slot]) {
        // G(child, 0, r), zero for r = 0 (a motion takes at least one step to find; a give-up
        // too, but needs no budget).
        if (r >= 1) all_fail *= 1.0 - reach_[node_block[static_cast<std::size_t>(child)] + (r - 1)];
      }
      after[r] = r == 0 && backtracking ? below_gives_up : 1.0 - all_fail;
    }
    fill_block(mdp, n, convolve_execution(problem.action(n), after, below_gives_up), reach_.data() + i * block,
               backtracking ? win_.data() + i * win_size : nullptr);
  }

  // Lower bound: C_k[l][s][b], the value of committing to k, one block per position.
  commit_.assign(positions * block, 0.0);
  lengths_.resize(static_cast<std::size_t>(skeleton_count_));
  path_start_.resize(static_cast<std::size_t>(skeleton_count_));
  commit_block_.assign(positions, kNoTable);
  reach_block_.assign(positions, kNoTable);
  if (backtracking) win_block_.assign(positions, kNoTable);
  std::size_t start = 0;
  for (int k = 0; k < skeleton_count_; ++k) {
    const int length = problem.skeleton_length(k);
    lengths_[static_cast<std::size_t>(k)] = length;
    path_start_[static_cast<std::size_t>(k)] = start;
    for (int l = length; l-- > 0;) {
      const int n = problem.action_at(k, l);
      const std::size_t position = start + static_cast<std::size_t>(l);
      commit_block_[position] = position * block;
      if (problem.members(n).front() == k) {
        reach_block_[position] = node_block[static_cast<std::size_t>(n)];
        if (backtracking) win_block_[position] = node_block[static_cast<std::size_t>(n)] / block * win_size;
      }
      // After refining n with r >= 0 steps left: success if n completes a skeleton (every
      // skeleton ending at n shares k's execution time), else C_k[l + 1][0][r].
      for (std::size_t r = 0; r < deadline; ++r) {
        if (problem.completes_a_skeleton(n)) {
          after[r] = 1.0;
        } else {
          after[r] = r >= 1 ? commit_[(position + 1) * block + (r - 1)] : 0.0;
        }
      }
      fill_block(mdp, n, convolve_execution(problem.action(n), after, 0.0), commit_.data() + position * block, nullptr);
    }
    start += static_cast<std::size_t>(length);
  }
}

}  // namespace ontime
