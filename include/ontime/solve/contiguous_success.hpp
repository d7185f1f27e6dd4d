#pragma once
// PS of Eq. (1) (SPEC §3): the probability that refining one skeleton contiguously, action
// after action, finishes refinement and execution by the deadline, with the planning time
// of its current action conditioned on the steps already spent on it.
//
// Computes, for skeleton k at position l with `spent` = PT_k steps on its current action a
// and `used` = CT + ET_k steps of the deadline gone,
//   PS = (1 / S_a(spent)) * sum_{t=1}^{D-used} p_a(spent + t) * G(k, l, used + t)
// where G(k, l, v) = E_a(D - v) for the last action, and otherwise
//   G(k, l, v) = sum_x e_a(x) * AGG_{k' in N(k,l)} PS(k', l+1, 0, v + x).
// With rewards (SPEC §8), PS is the expected reward of that contiguous refinement instead: the
// last action's E_a(D - v) becomes sum_x e_a(x) R_k(v + x) over finishes v + x <= D, and a
// sharing skeleton that completes is worth its reward R_k'(u) instead of 1; without rewards
// the tables are the success probabilities to the bit.
// Eq. (1) depends on CT and ET only through their sum, so G is one table of D + 1 values per
// (skeleton, position): everything that does not depend on `spent` is computed once, when the
// table is built, and a query is one dot product of at most D - used terms.
//
// Two more tables per (skeleton, position) make most queries O(1): PS with nothing yet spent on
// the action (every skeleton the allocator has not just worked on), and an upper bound on PS
// whatever was spent (the largest G(v) beyond `used`, as PS averages G over the planning time),
// with which a caller can skip skeletons that cannot win.
//
// Cost: building is O(sum_k A_k * D * (D + |supp e| * |N|)) time and O(sum_k A_k * D) memory; a
// query is O(1) with nothing spent and O(D - used) otherwise, with no allocation.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "ontime/mdp/mdp.hpp"

namespace ontime {

// How Eq. (1) combines the skeletons N(k, l) that share an action.
enum class Aggregation {
  sum,   // Eq. (1) as printed; reproduces the paper's Table I
  max,   // as the paper's text describes
  self,  // only k' = k: each skeleton on its own (used by `dp`)
};

// The aggregation's name: "sum", "max" or "self".
std::string_view to_string(Aggregation aggregation) noexcept;
// Parses "sum", "max" or "self"; throws UsageError otherwise.
Aggregation parse_aggregation(std::string_view text);

class ContiguousSuccessTable {
 public:
  // Builds the tables for `mdp` (which must outlive it). Throws UsageError with chains or expiry.
  ContiguousSuccessTable(const Mdp& mdp, Aggregation aggregation);

  // How the tables combine sharing skeletons.
  Aggregation aggregation() const noexcept { return aggregation_; }

  // PS(k, l, CT, ET) with `spent` steps already on action l of k and used = CT + ET.
  double success_probability(int k, int l, Steps spent, Steps used) const noexcept;

  // The same, read off an MDP state (0 when k has nothing left to refine).
  double success_probability(const State& state, int k) const noexcept;

  // A number >= success_probability(state, k), read from a table.
  double upper_bound(const State& state, int k) const noexcept;

  // Table reads for skeleton k at position l (which must exist), used = CT + ET_k: PS with
  // nothing spent on the action, and a bound on PS whatever was spent.
  double fresh_success_probability(int k, int l, std::int64_t used) const noexcept {
    return used < deadline_ ? fresh_[slot(k, l, used)] : 0.0;
  }
  double upper_bound(int k, int l, std::int64_t used) const noexcept {
    return used < deadline_ ? bound_[slot(k, l, used)] : 0.0;
  }

 private:
  std::size_t slot(int k, int l, std::int64_t used) const noexcept {
    return (offsets_[static_cast<std::size_t>(k)] + static_cast<std::size_t>(l)) *
               (static_cast<std::size_t>(deadline_) + 1) +
           static_cast<std::size_t>(used);
  }

  const Mdp* mdp_;
  Aggregation aggregation_;
  Steps deadline_;
  std::vector<std::size_t> offsets_;  // first (k, 0) slot of skeleton k
  // Per (k, l) slot: G(k, l, v) for v = 0 .. D + 1 (zero at v = 0 and v = D + 1).
  std::vector<double> continuation_;
  // Per action: p(t) for t = 0 .. 2D, zero-padded so a query needs no bounds checks.
  std::vector<double> planning_;
  // Per action: survival S(spent) for spent = 0 .. D - 1.
  std::vector<double> survival_;
  // Per (k, l) slot, for used = 0 .. D: PS(k, l, 0, used), and a bound on PS(k, l, any, used).
  std::vector<double> fresh_;
  std::vector<double> bound_;
  // Covers the rounding of a query's sum (at most D terms, each off by a few ulps).
  static constexpr double kBoundMargin = 1.0 + 1e-9;
};

}  // namespace ontime
