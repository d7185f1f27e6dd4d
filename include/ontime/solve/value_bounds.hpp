#pragma once
// Certified bounds on the optimal success probability (or expected reward) V*(s) of any state, from tables
// (docs/theory.md, "Certified bounds on the optimum").
//
// lower(s): the exact success probability of the best commit policy, which from s refines
// one skeleton k at every step until the episode ends. It is the value of a real policy, so
// lower(s) <= V*(s); lower_choice(s) names the skeleton, and commit(s, k) is the value of
// committing to k.
//
// upper(s): the clairvoyant relaxation. Planning and execution times are drawn before the
// episode and revealed to an allocator that knows them all; success needs some skeleton whose
// remaining planning and execution fit the time left. With the remaining actions of distinct
// groups in disjoint subtrees of the prefix tree, its probability is
//   upper(s) = 1 - prod over groups g of (1 - G(n_g, PT_g, D - CT - ET_g)),
// G computed exactly per node by a recursion over the tree; V*(s) <= upper(s). On problems
// whose prefix tree is one path (one skeleton, or skeletons that are prefixes of each other)
// both bounds equal V*.
//
// With rewards (SPEC §8), V* is the optimal expected reward and the bounds are scaled to it:
// commit(s, k) is the commit policy's success probability times the least reward it can earn
// (the reward at the deadline of k or of a skeleton completed on k's way, a prefix of k), so
// still at most that policy's expected reward; upper(s) is the clairvoyant success probability times the
// largest reward of any skeleton. Without rewards both factors are 1, and the bounds are the
// success-probability bounds above to the bit.
//
// A state is anything with time, refined[k], spent[k] and execution[k] (State, or the exact
// solver's fixed-size copy of it) reachable from the start. A skeleton contributes nothing
// when it is fully refined, when spent >= D (no further step can find its motion) or when
// CT + ET_k >= D; in particular slots blanked with spent or execution above D + 1 (the exact
// solver's keys of skeletons that cannot succeed) are ignored.
//
// With backtracking (SPEC §7) both still hold, each for a reason of its own (docs/theory.md):
// commit(s, k) is the probability that committing to k succeeds before any of its actions gives
// up, at most the commit policy's value (which goes on after a give-up), so still a lower bound
// on V*; upper(s) is the clairvoyant relaxation of the problem in which a give-up ends the
// episode in success (a give-up is worth at most 1), so a group contributes, besides its
// completions, the chance that some action of its subtree gives up, also where its own budget
// is spent (CT + ET_k >= D, but CT + 1 < D). The restore values are not read: the relaxation
// never needs them, and the commit bound never gets there.
//
// With exogenous chains or expiry (SPEC §9) upper(s) is still an upper bound: it is the
// clairvoyant relaxation of the problem with every execution that depends on a chain taking 0
// steps and no action expiring. A success of any policy needs the static part of some skeleton's
// remaining planning and execution to fit the time left, which is what the relaxation counts (a
// wait only uses time), and a success is worth at most the largest reward. The commit tables
// read the static distributions only, so they would overrate a commit there: commit(s, k) and
// lower(s) are 0 (sound, vacuous) and lower_choice(s) is -1. The exact value of a commit with
// chains is TimedContiguousSuccess's (memoised, so not something these shared tables can hold).
//
// Cost: the tables hold (nodes + sum of skeleton lengths) * D^2 doubles, built in
// O((nodes + sum of lengths) * D^2) time; the constructor throws ResourceLimitError past
// `max_table_entries`. Each bound is then O(K) table lookups, with no allocation. A
// ValueBounds refers to its Mdp, which must outlive it.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "ontime/mdp/mdp.hpp"

namespace ontime {

class ValueBounds {
 public:
  // 2^26 doubles: 512 MiB.
  static constexpr std::size_t kDefaultMaxTableEntries = std::size_t{1} << 26;

  // Precomputes the tables. Throws ResourceLimitError when they would hold more than
  // `max_table_entries` doubles.
  explicit ValueBounds(const Mdp& mdp, std::size_t max_table_entries = kDefaultMaxTableEntries);

  // The exact success probability of refining skeleton k at every step from `state`.
  template <class S>
  double commit(const S& state, int k) const noexcept;

  // A lower bound on V*(state): the largest commit value over the skeletons.
  template <class S>
  double lower(const S& state) const noexcept {
    const int k = lower_choice(state);
    return k < 0 ? 0.0 : commit(state, k);
  }

  // The skeleton lower() commits to (the lowest index on ties), -1 when lower() is 0.
  template <class S>
  int lower_choice(const S& state) const noexcept;

  // An upper bound on V*(state): the success probability of the clairvoyant relaxation.
  template <class S>
  double upper(const S& state) const noexcept;

  // The same from one skeleton's fields (the exact solver's successors, before they are whole
  // states): commit(k, ...) is commit(state, k); group_upper is G of the group whose next
  // action is k's (the clairvoyant success probability of that subtree alone, with the budget
  // D - time - execution), where k must be the group's lowest index.
  double commit(int k, int refined, std::uint16_t spent, std::uint16_t execution, std::int64_t time) const noexcept {
    const auto slot = static_cast<std::size_t>(k);
    const std::size_t at = cell(slot, refined, spent, execution, time);
    if (at == kNoTable) return 0.0;
    return commit_[commit_block_[path_start_[slot] + static_cast<std::size_t>(refined)] + at] * reward_floor_[slot];
  }
  double group_upper(int k, int refined, std::uint16_t spent, std::uint16_t execution,
                     std::int64_t time) const noexcept {
    const auto slot = static_cast<std::size_t>(k);
    if (refined >= lengths_[slot]) return 0.0;
    const std::size_t position = path_start_[slot] + static_cast<std::size_t>(refined);
    const std::size_t block = reach_block_[position];
    if (block == kNoTable) return 0.0;
    const std::size_t at = cell(slot, refined, spent, execution, time);
    if (at != kNoTable) return reach_[block + at];
    // With backtracking, a spent budget still leaves the give-ups of the subtree.
    if (win_.empty() || spent >= deadline_ || time + 1 >= deadline_) return 0.0;
    return win_[win_block_[position] + spent];
  }

  // Doubles the tables hold.
  std::size_t table_entries() const noexcept { return commit_.size() + reach_.size() + win_.size(); }
  const Mdp& mdp() const noexcept { return *mdp_; }

 private:
  static constexpr std::size_t kNoTable = static_cast<std::size_t>(-1);

  // The index of (spent, budget) in a D x D block when skeleton k can still contribute
  // (actions left, spent < D, budget D - CT - ET_k >= 1), else kNoTable.
  std::size_t cell(std::size_t k, int refined, std::uint16_t spent, std::uint16_t execution,
                   std::int64_t time) const noexcept {
    if (refined >= lengths_[k]) return kNoTable;
    const std::int64_t budget = std::int64_t{deadline_} - time - execution;
    if (spent >= deadline_ || budget < 1) return kNoTable;
    return static_cast<std::size_t>(spent) * static_cast<std::size_t>(deadline_) + static_cast<std::size_t>(budget - 1);
  }
  template <class S>
  std::size_t cell(const S& state, std::size_t k) const noexcept {
    return cell(k, state.refined[k], state.spent[k], state.execution[k], state.time);
  }

  const Mdp* mdp_;
  int skeleton_count_;
  Steps deadline_;
  std::vector<int> lengths_;             // A_k
  std::vector<std::size_t> path_start_;  // start of skeleton k's positions in the per-position arrays
  // Per position (k, l): the start of C_k[l] in commit_, a D x D block over (spent, budget - 1).
  std::vector<std::size_t> commit_block_;
  // Per position (k, l): the start of G of the action at l in reach_ (a D x D block), when k
  // is the lowest-index skeleton through that action (the one that speaks for its group);
  // kNoTable otherwise.
  std::vector<std::size_t> reach_block_;
  std::vector<double> commit_;
  std::vector<double> reach_;
  // Backtracking only (empty otherwise): per node, W(n, s) for s in [0, D], the chance that some
  // action of its subtree gives up; per position, where the group's W starts (as reach_block_).
  std::vector<double> win_;
  std::vector<std::size_t> win_block_;
  // Rewards (SPEC §8): per skeleton its least reward (at the deadline), and the largest value.
  std::vector<double> reward_floor_;
  double max_reward_ = 1.0;
};

template <class S>
double ValueBounds::commit(const S& state, int k) const noexcept {
  if (k < 0 || k >= skeleton_count_) return 0.0;
  const auto slot = static_cast<std::size_t>(k);
  return commit(k, state.refined[slot], state.spent[slot], state.execution[slot], state.time);
}

template <class S>
int ValueBounds::lower_choice(const S& state) const noexcept {
  int best = -1;
  double best_value = 0.0;
  for (int k = 0; k < skeleton_count_; ++k) {
    const double value = commit(state, k);
    if (value > best_value) {
      best_value = value;
      best = k;
    }
  }
  return best;
}

template <class S>
double ValueBounds::upper(const S& state) const noexcept {
  double all_fail = 1.0;
  for (int k = 0; k < skeleton_count_; ++k) {
    // 0 for a skeleton that is not its group's lowest index: another member speaks for it.
    const auto slot = static_cast<std::size_t>(k);
    const double group = group_upper(k, state.refined[slot], state.spent[slot], state.execution[slot], state.time);
    if (group > 0.0) all_fail *= 1.0 - group;
  }
  return (1.0 - all_fail) * max_reward_;
}

}  // namespace ontime
