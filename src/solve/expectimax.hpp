#pragma once
// Internal: memoised expectimax over the reachable states of the MDP, without recursion.
//
// V(s) = max over c in choices(s) of  sum_o P(o | s, c) * ([o is success] R(o) + [o running] V(o)),
// 0 when there is no choice; R(o) is the completed skeleton's reward at its finish (SPEC §8), 1
// without rewards (V is then the success probability, to the bit: p * 1 is p). `optimal` maximises over every useful
// choice; exact evaluation passes the one choice an allocator makes. Time only grows along a path, so the reachable
// states form a DAG of depth at most D; an explicit stack keeps deep deadlines off the call
// stack, and one item buffer used as a stack avoids allocation per state.
//
// The memo is an open-addressing hash table (absl::flat_hash_map): no node per state, hashes
// kept beside the keys. Where the deadline and skeleton count allow, states are packed into
// 16- or 32-byte keys (PackedState), so that a state costs 33 or 49 bytes of table slot
// instead of the ~140 bytes of a node-based map of full states.

#include <absl/container/flat_hash_map.h>
#include <absl/hash/hash.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "ontime/mdp/mdp.hpp"
#include "ontime/util/error.hpp"

namespace ontime::detail {

struct ExpectimaxEntry {
  double value;
  int choice;  // the maximising choice, -1 when there was none
};

// A state in 8 * Words bytes: CT in 16 bits, then refined, spent and execution of each
// skeleton in 8 bits each. Exact when 2 + 3K <= 8 * Words and every counter stays below 255
// (D <= 253: spent and execution never exceed D + 1, and 255 is free for markers).
template <std::size_t Words>
struct PackedState {
  std::array<std::uint64_t, Words> words{};

  friend bool operator==(const PackedState& a, const PackedState& b) noexcept {
    std::uint64_t difference = 0;
    for (std::size_t i = 0; i < Words; ++i) difference |= a.words[i] ^ b.words[i];
    return difference == 0;
  }
};

// Mixes the words and finishes with MurmurHash3's 64-bit avalanche, inline: the generic
// absl::Hash of an array calls out of line and showed up as a tenth of the solve time.
struct PackedStateHash {
  template <std::size_t Words>
  std::size_t operator()(const PackedState<Words>& state) const noexcept {
    std::uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (std::size_t i = 0; i < Words; ++i) h = (h ^ (h >> 29) ^ state.words[i]) * 0xbf58476d1ce4e5b9ULL;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ULL;
    return static_cast<std::size_t>(h ^ (h >> 33));
  }
};

// The fewest 64-bit words a packed state of this MDP needs (2 or 4), or 0 when it cannot be
// packed.
inline std::size_t packed_words(const Mdp& mdp) noexcept {
  if (mdp.deadline() > 253) return 0;
  const int bytes = 2 + 3 * mdp.skeleton_count();
  return bytes <= 16 ? 2 : bytes <= 32 ? 4 : 0;
}

// A whole state in a fixed 82 bytes (at most kMaxExactSkeletons skeletons; unused slots zero):
// the state the search works on, and its key where the deadline or the skeleton count is too
// large for a PackedState.
struct CompactState {
  std::uint16_t time = 0;
  std::array<std::uint8_t, kMaxExactSkeletons> refined{};
  std::array<std::uint16_t, kMaxExactSkeletons> spent{};
  std::array<std::uint16_t, kMaxExactSkeletons> execution{};

  friend bool operator==(const CompactState&, const CompactState&) = default;
};
static_assert(sizeof(CompactState) == 2 + 16 + 32 + 32, "CompactState must have no padding: it is hashed as bytes");

// The most restore values (Problem::culprit_slot_count actions backtracking may blame and
// Problem::timed_slot_count timed actions, together) in a problem the exact solvers take.
inline constexpr int kMaxExactCulpritSlots = 16;

// A CompactState with backtracking's restore values (SPEC §7): the state the exact solvers work
// on, and its key, for a problem whose actions may backtrack. (A type of its own, so that the
// states of every other problem stay 82 bytes.)
struct CompactBacktrackState : CompactState {
  std::array<std::uint16_t, kMaxExactCulpritSlots> restore{};

  friend bool operator==(const CompactBacktrackState&, const CompactBacktrackState&) = default;
};
static_assert(sizeof(CompactBacktrackState) == sizeof(CompactState) + 32,
              "CompactBacktrackState must have no padding: it is hashed as bytes");

// With exogenous chains or expiry (SPEC §9): the chains' joint state, and in `restore` the static
// execution before each timed action (by Problem::timed_slot). The state and key of the exact
// solvers for such a problem.
struct CompactTimedState : CompactBacktrackState {
  std::uint16_t chains = 0;

  friend bool operator==(const CompactTimedState&, const CompactTimedState&) = default;
};
static_assert(sizeof(CompactTimedState) == sizeof(CompactBacktrackState) + 2,
              "CompactTimedState must have no padding: it is hashed as bytes");

// The slots of State::restore a problem uses: its culprits', then its timed actions'.
inline int recorded_slots(const Problem& problem) noexcept {
  return problem.culprit_slot_count() + problem.timed_slot_count();
}

// The fixed-size copy of a state: a CompactState, or with restore values a CompactBacktrackState
// (`culprit_slots` of them: recorded_slots), or with the chains' state too a CompactTimedState.
template <class Compact = CompactState>
Compact compact(const State& state, int skeleton_count, int culprit_slots = 0) noexcept {
  Compact out;
  out.time = state.time;
  if constexpr (kHoldsChains<Compact>) out.chains = state.chains;
  for (int k = 0; k < skeleton_count; ++k) {
    const auto slot = static_cast<std::size_t>(k);
    out.refined[slot] = state.refined[slot];
    out.spent[slot] = state.spent[slot];
    out.execution[slot] = state.execution[slot];
  }
  if constexpr (kHoldsRestore<Compact>) {
    for (int c = 0; c < culprit_slots; ++c) {
      out.restore[static_cast<std::size_t>(c)] = state.restore[static_cast<std::size_t>(c)];
    }
  } else {
    (void)culprit_slots;
  }
  return out;
}

template <std::size_t Words>
PackedState<Words> pack(const CompactState& state, int skeleton_count) noexcept {
  std::array<std::uint8_t, 8 * Words> bytes{};
  bytes[0] = static_cast<std::uint8_t>(state.time & 0xFF);
  bytes[1] = static_cast<std::uint8_t>(state.time >> 8);
  for (int k = 0; k < skeleton_count; ++k) {
    const auto slot = static_cast<std::size_t>(k);
    bytes[2 + 3 * slot] = state.refined[slot];
    bytes[3 + 3 * slot] = static_cast<std::uint8_t>(state.spent[slot]);
    bytes[4 + 3 * slot] = static_cast<std::uint8_t>(state.execution[slot]);
  }
  PackedState<Words> packed;
  std::memcpy(packed.words.data(), bytes.data(), bytes.size());
  return packed;
}

// The state a CompactState holds, written into `out` (sized for `compact`'s skeletons, and its
// restore values for a CompactBacktrackState's).
template <class Compact>
void expanded(const Compact& compact, State& out) noexcept {
  if constexpr (kHoldsRestore<Compact>) {
    for (std::size_t c = 0; c < compact.restore.size() && c < out.restore.capacity(); ++c) {
      out.restore[c] = compact.restore[c];
    }
  }
  if constexpr (kHoldsChains<Compact>) out.chains = compact.chains;
  out.time = compact.time;
  for (std::size_t k = 0; k < compact.refined.size(); ++k) {
    out.refined[k] = compact.refined[k];
    out.spent[k] = compact.spent[k];
    out.execution[k] = compact.execution[k];
  }
}

// Hashes a compact state (of either kind) as its bytes: it has no padding.
struct CompactStateHash {
  template <class Compact>
  std::size_t operator()(const Compact& state) const noexcept {
    return absl::Hash<std::string_view>{}(std::string_view(reinterpret_cast<const char*>(&state), sizeof(Compact)));
  }
};

// Above any reachable PT or ET (its low byte, 255, is above them too when packed): the value of
// a blanked slot.
inline constexpr std::uint16_t kBlankCounter = 0xFFFF;

// Blanks, in place, the slots of skeletons whose group can no longer succeed (refined 0, spent
// and execution kBlankCounter): they influence neither the value nor the choices, so states
// that differ only there are one state to the exact solvers. A blanked state evolves like the
// original (a blanked skeleton shares no action with a skeleton that can still succeed).
inline void blank_hopeless(const Mdp& mdp, CompactState& state) noexcept {
  for (int k = 0; k < mdp.skeleton_count(); ++k) {
    const int action = mdp.next_action(state, k);
    if (action >= 0 && mdp.group_can_succeed(state, action)) continue;
    const auto slot = static_cast<std::size_t>(k);
    state.refined[slot] = 0;
    state.spent[slot] = kBlankCounter;
    state.execution[slot] = kBlankCounter;
  }
}

// Throws UsageError when the problem has more skeletons, or more actions that backtracking may
// blame, than the exact solvers' keys hold.
inline void require_exact_size(const Mdp& mdp, const std::string& what) {
  if (mdp.skeleton_count() > kMaxExactSkeletons) {
    throw UsageError(what + ": the instance has " + std::to_string(mdp.skeleton_count()) +
                     " skeletons; exact solving and exact evaluation take at most " +
                     std::to_string(kMaxExactSkeletons) + " (use a sampled evaluation or an approximate allocator)");
  }
  if (mdp.problem().culprit_slot_count() > kMaxExactCulpritSlots) {
    throw UsageError(what + ": the instance has " + std::to_string(mdp.problem().culprit_slot_count()) +
                     " actions that backtracking may blame; exact solving and exact evaluation take at most " +
                     std::to_string(kMaxExactCulpritSlots) + " (use a sampled evaluation or an approximate allocator)");
  }
  if (mdp.problem().timed_slot_count() > kMaxExactCulpritSlots) {
    throw UsageError(what + ": the instance has " + std::to_string(mdp.problem().timed_slot_count()) +
                     " timed actions (chains or expiry); exact solving and exact evaluation take at most " +
                     std::to_string(kMaxExactCulpritSlots));
  }
  if (recorded_slots(mdp.problem()) > kMaxExactCulpritSlots) {
    throw UsageError(what + ": the instance has " + std::to_string(mdp.problem().culprit_slot_count()) +
                     " actions that backtracking may blame and " + std::to_string(mdp.problem().timed_slot_count()) +
                     " timed actions; exact solving and exact evaluation take at most " +
                     std::to_string(kMaxExactCulpritSlots) + " together");
  }
}

// With chains or expiry (SPEC §9): R of a success, from the table of its plan's values over
// every start (Mdp::execution_table, so each value is execution_value's to the bit), made once
// per plan. A plan is its skeleton, its ET and the executions before its timed actions, so the
// tables' number does not grow with the chains' states, and each success costs a look-up. (With
// backtracking too the culprits' restore values, which a plan's execution never reads, are left
// out of the key.) Past kMaxCells cached values (256 MiB) a success is valued without a table.
// One per thread.
class PlanValues {
 public:
  double reward(const Mdp& mdp, const CompactTimedState& state, int choice) {
    const int k = mdp.completed_skeleton(state, choice);
    Key key{static_cast<std::uint16_t>(k), state.execution[static_cast<std::size_t>(k)], state.restore};
    std::fill_n(key.restore.begin(), mdp.problem().culprit_slot_count(), std::uint16_t{0});
    auto found = tables_.find(key);
    if (found == tables_.end()) {
      if (cells_ > kMaxCells)
        return mdp.execution_value(k, state.time, state.chains, state.restore.data(), key.execution);
      found = tables_.try_emplace(key).first;
      mdp.execution_table(k, state.restore.data(), key.execution, found->second);
      cells_ += found->second.size();
    }
    return found->second[static_cast<std::size_t>(state.time) * static_cast<std::size_t>(mdp.joint_chain_states()) +
                         state.chains];
  }

  // What the tables hold: their values and the map's slots.
  std::uint64_t bytes() const noexcept {
    return cells_ * sizeof(double) + tables_.capacity() * (sizeof(Key) + sizeof(std::vector<double>) + 1);
  }

 private:
  struct Key {
    std::uint16_t skeleton;
    std::uint16_t execution;
    std::array<std::uint16_t, kMaxExactCulpritSlots> restore;
    friend bool operator==(const Key&, const Key&) = default;
  };
  static_assert(sizeof(Key) == 4 + 2 * kMaxExactCulpritSlots,
                "PlanValues::Key must have no padding: it is hashed as bytes");
  static constexpr std::size_t kMaxCells = std::size_t{1} << 25;
  absl::flat_hash_map<Key, std::vector<double>, CompactStateHash> tables_;
  std::size_t cells_ = 0;
};

// The search runs on compact states (the Mdp's functions are templates on the state type): a
// copy is a plain 82-byte copy (114 with backtracking's restore values), with no indirection.
//
// Policy provides:
//   using Compact = CompactState or CompactBacktrackState;  // the state type (the latter for backtracking)
//   void choices(const Compact&, std::vector<int>& out) const;  // in increasing preference on ties
//   Key key(const Compact&) const;   // states with one key share a value; Compact or PackedState
template <class Policy>
class Expectimax {
 public:
  using Compact = typename Policy::Compact;
  using Key = std::remove_cvref_t<decltype(std::declval<const Policy&>().key(std::declval<const Compact&>()))>;
  using Hash = std::conditional_t<std::is_same_v<Key, Compact>, CompactStateHash, PackedStateHash>;
  using Memo = absl::flat_hash_map<Key, ExpectimaxEntry, Hash>;

  Expectimax(const Mdp& mdp, Policy policy, std::size_t max_states, double tie_tolerance, std::string what)
      : mdp_(&mdp),
        policy_(std::move(policy)),
        max_states_(max_states),
        tie_tolerance_(tie_tolerance),
        what_(std::move(what)) {
    require_exact_size(mdp, what_);
  }

  // A condition checked every few thousand states: once it returns true, solve throws Cancelled
  // (the states solved so far are kept).
  void set_stop(std::function<bool()> stop) { stop_ = std::move(stop); }

  ExpectimaxEntry solve(const State& start_state) {
    const Compact start = compact_of(start_state);
    const Key start_key = policy_.key(start);
    if (const auto found = memo_.find(start_key); found != memo_.end()) return found->second;
    push(start, start_key);
    while (!frames_.empty()) {
      const std::size_t top = frames_.size() - 1;
      bool descended = false;
      while (frames_[top].cursor < frames_[top].end) {
        const Item& item = items_[frames_[top].cursor++];
        if (item.status == Status::running && !memo_.contains(item.key)) {
          const Compact next = item.next;  // push may move the items
          const Key next_key = item.key;
          push(next, next_key);
          descended = true;
          break;
        }
      }
      if (descended) continue;
      finish(top);
    }
    return memo_.at(start_key);
  }

  const Memo& memo() const noexcept { return memo_; }
  Key key_of(const State& state) const { return policy_.key(compact_of(state)); }
  const Policy& policy() const noexcept { return policy_; }

  // Memory held by the memo (table slots and their control bytes).
  std::size_t memo_bytes() const noexcept { return memo_.capacity() * (sizeof(typename Memo::slot_type) + 1); }

 private:
  struct Item {
    int choice = -1;
    Status status = Status::running;
    double probability = 0.0;
    Compact next;
    Key key;  // of `next`, when running
  };
  struct Frame {
    Key key;
    std::size_t begin, end, cursor;
  };

  Compact compact_of(const State& state) const {
    return compact<Compact>(state, mdp_->skeleton_count(), recorded_slots(mdp_->problem()));
  }

  void push(const Compact& state, const Key& key) {
    Frame frame{key, items_.size(), 0, items_.size()};
    choices_.clear();
    policy_.choices(state, choices_);
    for (const int choice : choices_) {
      mdp_->for_each_outcome(state, choice, [&](double probability, Status status, const Compact& next) {
        items_.push_back(
            Item{choice, status, probability, next, status == Status::running ? policy_.key(next) : Key{}});
      });
    }
    frame.end = items_.size();
    frames_.push_back(frame);
  }

  void finish(std::size_t top) {
    const Frame frame = frames_[top];
    ExpectimaxEntry best{0.0, -1};
    double best_value = -1.0;
    for (std::size_t i = frame.begin; i < frame.end;) {
      const int choice = items_[i].choice;
      double value = 0;
      for (; i < frame.end && items_[i].choice == choice; ++i) {
        const Item& item = items_[i];
        if (item.status == Status::success) {
          value += item.probability * success_reward(item.next, item.choice);
        } else if (item.status == Status::running) {
          value += item.probability * memo_.at(item.key).value;
        }
      }
      if (value > best_value + tie_tolerance_) {
        best_value = value;
        best = {value, choice};
      }
    }
    if (stop_ && (memo_.size() & (kStopCheckInterval - 1)) == 0 && stop_()) {
      throw Cancelled(what_ + ": stopped at the caller's request after " + std::to_string(memo_.size()) + " states");
    }
    if (memo_.size() >= max_states_) {
      throw ResourceLimitError(what_ + ": reached the cap of " + std::to_string(max_states_) +
                               " states (the max-states parameter) before finishing (about " +
                               std::to_string(memo_bytes() >> 20) + " MiB held, " +
                               std::to_string((memo_bytes() + memo_bytes() / 2) >> 20) +
                               " MiB while the table last doubled); raise the cap or use an approximate allocator");
    }
    memo_.emplace(frame.key, best);
    items_.resize(frame.begin);
    frames_.pop_back();
  }

  // R of a success (SPEC §8); with chains or expiry (SPEC §9) from the plans' tables.
  double success_reward(const Compact& state, int choice) {
    if constexpr (kHoldsChains<Compact>) {
      if (mdp_->is_timed()) return plans_.reward(*mdp_, state, choice);
    }
    return mdp_->success_reward(state, choice);
  }
  PlanValues plans_;

  // States between two checks of the stop condition: rare enough to cost nothing, frequent
  // enough (well under a millisecond of work) to stop promptly.
  static constexpr std::size_t kStopCheckInterval = 4096;

  const Mdp* mdp_;
  Policy policy_;
  std::function<bool()> stop_;
  std::size_t max_states_;
  double tie_tolerance_;
  std::string what_;
  Memo memo_;
  std::vector<Frame> frames_;
  std::vector<Item> items_;
  std::vector<int> choices_;
};

// Choices and state keys of the optimal solver; Words > 0 packs keys into that many 64-bit
// words (detail::pack), 0 keys by the whole state (detail::compact).
template <std::size_t Words>
class OptimalPolicy {
 public:
  using Compact = CompactState;
  explicit OptimalPolicy(const Mdp& mdp) : mdp_(&mdp) {}

  void choices(const Compact& state, std::vector<int>& out) const {
    for (const int choice : mdp_->useful_choices(state)) out.push_back(choice);
  }

  // Skeletons in a group that can no longer succeed influence nothing: blank_hopeless
  // blanks their slots so that states differing only there share one memo entry.
  auto key(const CompactState& state) const {
    CompactState key = state;
    blank_hopeless(*mdp_, key);
    if constexpr (Words > 0) {
      return pack<Words>(key, mdp_->skeleton_count());
    } else {
      return key;
    }
  }

 private:
  const Mdp* mdp_;
};

// With backtracking (SPEC §7): states with their restore values, keyed whole. No slot is blanked:
// a step on a group that cannot succeed may still backtrack and restore an action others share.
// With chains or expiry (SPEC §9) the same with CompactTimedState (OptimalTimedPolicy): the
// chains' state and the executions before timed actions are part of the key.
template <class CompactType = CompactBacktrackState>
class OptimalRecordedPolicy {
 public:
  using Compact = CompactType;
  explicit OptimalRecordedPolicy(const Mdp& mdp) : mdp_(&mdp) {}

  void choices(const Compact& state, std::vector<int>& out) const {
    for (const int choice : mdp_->useful_choices(state)) out.push_back(choice);
  }
  static const Compact& key(const Compact& state) { return state; }

 private:
  const Mdp* mdp_;
};
using OptimalBacktrackPolicy = OptimalRecordedPolicy<CompactBacktrackState>;
using OptimalTimedPolicy = OptimalRecordedPolicy<CompactTimedState>;

}  // namespace ontime::detail
