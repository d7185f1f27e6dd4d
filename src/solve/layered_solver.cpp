#include "ontime/solve/layered_solver.hpp"

#include <absl/container/flat_hash_map.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "ontime/solve/optimal_solver.hpp"
#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/byte_packing.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/parallel.hpp"
#include "solve/expectimax.hpp"
#include "solve/scratch_directory.hpp"

namespace ontime {
namespace {

using detail::CompactState;
using detail::PackedState;
using detail::PackedStateHash;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// ---- the per-outcome codes of the scratch files ----
//
// One 32-bit code per outcome: where the successor sits in the next layer (a shard's place, or
// an entry of the layer's list of successors owned by other ranks), or success, failure; a
// successor from which a tolerance dropped groups is preceded by kExtrasCode, and its factor
// and boost are the next two doubles of the layer's extras file.
constexpr std::uint32_t kForeignBase = 0x8000'0000U;
constexpr std::uint32_t kSpecialBase = 0xFFFF'FFF0U;
constexpr std::uint32_t kSuccessCode = 0xFFFF'FFFFU;
constexpr std::uint32_t kFailureCode = 0xFFFF'FFFEU;
constexpr std::uint32_t kExtrasCode = 0xFFFF'FFFDU;

// The choice a split's step on the bounded subtrees stands for in the policy (mapped to the
// bounded skeleton with the best commit value when reported).
constexpr int kWeakChoice = -2;

// Where each skeleton's fields sit in a key: refined in just enough bits for the skeleton's
// length, PT and ET in just enough for 0 .. D + 1 and one more code for a blanked slot; in a
// split, one more bit flags the copies one layer on (a step went to the bounded subtrees). A
// skeleton's fields never straddle two words, so that rewriting them is a mask and an or.
class KeyLayout {
 public:
  KeyLayout(const Mdp& mdp, bool flag)
      : skeletons_(mdp.skeleton_count()),
        blank_code_(static_cast<std::uint64_t>(mdp.deadline()) + 2),
        counter_bits_(static_cast<int>(std::bit_width(blank_code_))) {
    int used = 0;
    const auto place = [&](int bits) {
      if (used + bits > 64) {
        ++words_;
        used = 0;
      }
      const int shift = used;
      used += bits;
      return std::pair{words_ - 1, shift};
    };
    for (int k = 0; k < skeletons_; ++k) {
      const int refined_bits = std::bit_width(static_cast<unsigned>(mdp.problem().skeleton_length(k)));
      const auto [word, shift] = place(refined_bits + 2 * counter_bits_);
      Field& field = fields_[static_cast<std::size_t>(k)];
      field = {word, shift, refined_bits, 0, 0};
      field.mask = ((std::uint64_t{1} << (refined_bits + 2 * counter_bits_)) - 1) << shift;
      field.blank = (blank_code_ << refined_bits | blank_code_ << (refined_bits + counter_bits_)) << shift;
    }
    if (flag) {
      const auto [word, shift] = place(1);
      flag_word_ = word;
      flag_bit_ = std::uint64_t{1} << shift;
    }
  }

  int words() const noexcept { return words_; }
  int word(int k) const noexcept { return fields_[static_cast<std::size_t>(k)].word; }
  std::uint64_t mask(int k) const noexcept { return fields_[static_cast<std::size_t>(k)].mask; }
  std::uint64_t blank(int k) const noexcept { return fields_[static_cast<std::size_t>(k)].blank; }
  // k's fields with these values, in place in its word.
  std::uint64_t value(int k, int refined, std::uint16_t spent, std::uint16_t execution) const noexcept {
    const Field& field = fields_[static_cast<std::size_t>(k)];
    return (static_cast<std::uint64_t>(refined) | code(spent) << field.refined_bits |
            code(execution) << (field.refined_bits + counter_bits_))
           << field.shift;
  }

  template <std::size_t W>
  bool flagged(const PackedState<W>& key) const noexcept {
    return flag_bit_ != 0 && (key.words[static_cast<std::size_t>(flag_word_)] & flag_bit_) != 0;
  }
  template <std::size_t W>
  void set_flag(PackedState<W>& key, bool on) const noexcept {
    if (flag_bit_ == 0) return;
    auto& word = key.words[static_cast<std::size_t>(flag_word_)];
    word = on ? word | flag_bit_ : word & ~flag_bit_;
  }

  template <std::size_t W>
  PackedState<W> encode(const CompactState& state) const noexcept {
    PackedState<W> key;
    for (int k = 0; k < skeletons_; ++k) {
      const auto slot = static_cast<std::size_t>(k);
      key.words[static_cast<std::size_t>(word(k))] |=
          value(k, state.refined[slot], state.spent[slot], state.execution[slot]);
    }
    return key;
  }

  template <std::size_t W>
  void decode(const PackedState<W>& key, int layer, CompactState& out) const noexcept {
    out.time = static_cast<std::uint16_t>(layer);
    const std::uint64_t counter_mask = (std::uint64_t{1} << counter_bits_) - 1;
    for (int k = 0; k < skeletons_; ++k) {
      const auto slot = static_cast<std::size_t>(k);
      const Field& field = fields_[slot];
      const std::uint64_t bits = key.words[static_cast<std::size_t>(field.word)] >> field.shift;
      out.refined[slot] = static_cast<std::uint8_t>(bits & ((std::uint64_t{1} << field.refined_bits) - 1));
      out.spent[slot] = counter(bits >> field.refined_bits & counter_mask);
      out.execution[slot] = counter(bits >> (field.refined_bits + counter_bits_) & counter_mask);
    }
  }

 private:
  struct Field {
    int word, shift, refined_bits;
    std::uint64_t mask, blank;
  };
  std::uint64_t code(std::uint16_t counter) const noexcept {
    return counter >= blank_code_ ? blank_code_ : std::uint64_t{counter};
  }
  std::uint16_t counter(std::uint64_t code) const noexcept {
    return code == blank_code_ ? detail::kBlankCounter : static_cast<std::uint16_t>(code);
  }

  int skeletons_;
  std::uint64_t blank_code_;
  int counter_bits_;
  int words_ = 1;
  int flag_word_ = 0;
  std::uint64_t flag_bit_ = 0;
  std::array<Field, kMaxExactSkeletons> fields_{};
};

// The rank that owns a key, and the shard of a rank's layer table a key falls into: two mixes
// of the key other than the tables' hash, so that keys still spread over each table.
template <std::size_t W>
std::uint64_t placement_hash(const PackedState<W>& key) noexcept {
  std::uint64_t h = 0x2545f4914f6cdd1dULL;
  for (const std::uint64_t word : key.words) h = (h ^ word) * 0x9e3779b97f4a7c15ULL;
  return h ^ (h >> 29);
}

// Memory one rank's forward pass may still take, shared by its threads: the tables ask before
// they grow, so that a cap ends the pass cleanly rather than the allocation failing.
class MemoryBudget {
 public:
  explicit MemoryBudget(std::uint64_t cap) : cap_(cap) {}
  // Takes `bytes` if the total stays within the cap (always when there is no cap).
  bool take(std::uint64_t bytes) noexcept {
    const std::uint64_t now = held_.fetch_add(bytes) + bytes;
    if (cap_ == 0 || now <= cap_) return true;
    held_.fetch_sub(bytes);
    return false;
  }
  void give(std::uint64_t bytes) noexcept { held_.fetch_sub(bytes); }
  std::uint64_t held() const noexcept { return held_.load(); }

 private:
  std::uint64_t cap_;
  std::atomic<std::uint64_t> held_{0};
};

// The places of one shard of the next layer: key -> index in the order keys arrived. Written
// here rather than taken from absl::flat_hash_map because the insertions are the forward pass's
// main cost and nearly all miss the caches: absl's prefetch brings only the control bytes,
// while a slot here holds the key and its index together, so one prefetch a few keys ahead
// brings what the probe reads (linear probing, at most half full). The keys, in index order,
// live beside it, reserved as the table grows.
template <std::size_t W>
class alignas(64) PlaceTable {  // on lines of its own: each shard's table is another thread's
 public:
  using Key = PackedState<W>;
  static constexpr std::uint32_t kEmpty = 0xFFFF'FFFFU;

  static std::uint64_t hash(const Key& key) noexcept { return PackedStateHash{}(key); }

  void prefetch(std::uint64_t hash) const noexcept {
    if (!slots_.empty()) __builtin_prefetch(&slots_[hash & mask_]);
  }

  // The key's index, inserting it (with the next index) if it is new; false, and nothing
  // inserted, when the table would have to grow past the budget.
  bool place(const Key& key, std::uint64_t hash, MemoryBudget& budget, std::uint32_t& index) {
    if (2 * (keys_.size() + 1) > slots_.size() && !grow(budget)) return false;
    for (std::size_t at = hash & mask_;; at = (at + 1) & mask_) {
      Slot& slot = slots_[at];
      if (slot.index == kEmpty) {
        slot = {key, static_cast<std::uint32_t>(keys_.size())};
        keys_.push_back(key);
        index = slot.index;
        return true;
      }
      if (slot.key == key) {
        index = slot.index;
        return true;
      }
    }
  }

  const std::vector<Key>& keys() const noexcept { return keys_; }
  std::uint64_t bytes() const noexcept { return slots_.capacity() * sizeof(Slot) + keys_.capacity() * sizeof(Key); }
  // Frees the table and the keys, giving their memory back to the budget.
  void clear(MemoryBudget& budget) {
    budget.give(bytes());
    std::vector<Slot>().swap(slots_);
    std::vector<Key>().swap(keys_);
    mask_ = 0;
  }

 private:
  struct Slot {
    Key key;
    std::uint32_t index = kEmpty;
  };
  bool grow(MemoryBudget& budget) {
    const std::size_t size = std::max<std::size_t>(1024, 2 * slots_.size());
    const std::uint64_t old_bytes = bytes();
    const std::uint64_t new_bytes = size * sizeof(Slot) + size / 2 * sizeof(Key);
    if (!budget.take(new_bytes)) return false;  // both arrays are held while the slots move
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(size, Slot{});
    keys_.reserve(size / 2);
    mask_ = slots_.size() - 1;
    for (const Slot& slot : old) {
      if (slot.index == kEmpty) continue;
      std::size_t at = hash(slot.key) & mask_;
      while (slots_[at].index != kEmpty) at = (at + 1) & mask_;
      slots_[at] = slot;
    }
    budget.give(old_bytes);
    budget.give(new_bytes - bytes());  // what the reservation did not use
    return true;
  }
  std::vector<Slot> slots_;
  std::vector<Key> keys_;
  std::size_t mask_ = 0;
};

// Why the forward pass ended early; the lowest nonzero reason over the ranks wins.
enum class Cut : std::uint8_t { none = 0, stop, states, memory, disk };

// A scratch file written or read in pieces, with the disk it holds counted; errors name the
// layer and the file.
class ScratchFile {
 public:
  ScratchFile(std::filesystem::path path, int layer, const char* mode)
      : path_(std::move(path)), layer_(layer), file_(std::fopen(path_.c_str(), mode)) {
    if (file_ == nullptr) fail("cannot open");
  }
  ~ScratchFile() {
    if (file_ != nullptr) std::fclose(file_);
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  template <class T>
  void write(const T* data, std::size_t count) {
    if (count != 0 && std::fwrite(data, sizeof(T), count, file_) != count) fail("cannot write to");
  }
  template <class T>
  void read(T* data, std::size_t count) {
    if (count != 0 && std::fread(data, sizeof(T), count, file_) != count) fail("cannot read back");
  }
  void close() {
    const bool failed = std::fclose(file_) != 0;
    file_ = nullptr;
    if (failed) fail("cannot write to");
  }

 private:
  [[noreturn]] void fail(const char* what) const {
    throw ResourceLimitError("layer " + std::to_string(layer_) + ": " + what + " the scratch file " + path_.string() +
                             " (disk full?); free space or set --scratch");
  }
  std::filesystem::path path_;
  int layer_;
  std::FILE* file_ = nullptr;
};

struct Bounds {
  double lower = 0;
  double upper = 0;
};

// What a split adds to the enumerated subtree: for each layer t, bounds on the success
// probability of the bounded subtrees alone, fresh, from CT = t (index D: nothing left).
struct WeakCluster {
  std::vector<double> lower;  // the best commit to one of their skeletons (a real policy)
  std::vector<double> upper;  // their clairvoyant chance, all of them together
  std::vector<int> commit;    // the skeleton (of the whole problem) of `lower`, -1 if none
};

// ---- successors ----

// Per action of the prefix tree, what a step on it touches, looked up once per search: the
// skeletons through it (its group when it is their next action), the child actions they move
// on to when it is refined, and those that end with it.
class TreeTables {
 public:
  struct Node {
    int rep = -1;  // lowest skeleton through it: the choice naming its group
    int position = 0;
    bool completes = false;
    std::uint32_t members_begin = 0, members_end = 0;    // in members()
    std::uint32_t children_begin = 0, children_end = 0;  // in children()
    std::uint32_t ending_begin = 0, ending_end = 0;      // in ending()
  };

  explicit TreeTables(const Problem& problem) : nodes_(static_cast<std::size_t>(problem.action_count())) {
    for (int a = 0; a < problem.action_count(); ++a) {
      Node& node = nodes_[static_cast<std::size_t>(a)];
      if (problem.position(a) < 0) continue;
      const std::span<const int> through = problem.members(a);
      node.rep = through.front();
      node.position = problem.position(a);
      node.completes = problem.completes_a_skeleton(a);
      node.members_begin = static_cast<std::uint32_t>(members_.size());
      members_.insert(members_.end(), through.begin(), through.end());
      node.members_end = static_cast<std::uint32_t>(members_.size());
      node.children_begin = static_cast<std::uint32_t>(children_.size());
      node.ending_begin = static_cast<std::uint32_t>(ending_.size());
      for (const int k : through) {
        if (node.position + 1 >= problem.skeleton_length(k)) {
          ending_.push_back(k);
          continue;
        }
        const int child = problem.action_at(k, node.position + 1);
        if (problem.members(child).front() == k) children_.push_back(child);
      }
      node.children_end = static_cast<std::uint32_t>(children_.size());
      node.ending_end = static_cast<std::uint32_t>(ending_.size());
    }
  }

  const Node& node(int action) const noexcept { return nodes_[static_cast<std::size_t>(action)]; }
  std::span<const int> members(const Node& node) const noexcept {
    return {members_.data() + node.members_begin, node.members_end - node.members_begin};
  }
  std::span<const int> children(const Node& node) const noexcept {
    return {children_.data() + node.children_begin, node.children_end - node.children_begin};
  }
  std::span<const int> ending(const Node& node) const noexcept {
    return {ending_.data() + node.ending_begin, node.ending_end - node.ending_begin};
  }

 private:
  std::vector<Node> nodes_;
  std::vector<int> members_, children_, ending_;
};

// The outcomes of every useful choice of a state, in the order of Mdp::useful_choices and
// Mdp::for_each_outcome, with the successors' keys built from the state's key: a successor
// differs in the chosen group's fields and in groups that cannot succeed any more at the next
// step (blanked, as detail::blank_hopeless does); with a tolerance, groups whose clairvoyant
// chance is below it are blanked too, their share noted. In a split, unflagged states have one
// more choice, a step on the bounded subtrees: its outcome is the same state one layer on,
// flagged. One walk serves both passes: the backward pass asks only for the probabilities.
//
// Groups are found from the skeletons that are not blanked: a blanked slot (refined 0) would
// name the first action, shared with skeletons elsewhere in the tree that are still alive.
template <std::size_t W>
class Successors {
 public:
  using Key = PackedState<W>;
  using Node = TreeTables::Node;

  struct Outcome {
    int choice = 0;  // a skeleton (the group's lowest index) or kWeakChoice
    double probability = 0;
    Status status = Status::running;
    Key key;              // running only
    bool extras = false;  // a tolerance dropped groups: the share below
    double factor = 1;    // product of (1 - G) over the dropped groups
    double boost = 0;     // best commit value among them
  };

  Successors(const Mdp& mdp, const TreeTables& tree, const KeyLayout& layout, const ValueBounds* bounds,
             double tolerance, bool split)
      : mdp_(&mdp),
        tree_(&tree),
        layout_(&layout),
        bounds_(bounds),
        tolerance_(tolerance),
        split_(split),
        deadline_(mdp.deadline()),
        skeletons_(mdp.skeleton_count()) {}

  // Calls sink(outcome) for every outcome, with keys (forward).
  template <class Sink>
  void expand(const Key& key, int t, Sink&& sink) {
    walk<true>(key, t, sink);
  }
  // Calls sink(outcome) for every outcome, with its choice and probability only, in the same
  // order (backward).
  template <class Sink>
  void probabilities(const Key& key, int t, Sink&& sink) {
    walk<false>(key, t, sink);
  }

  // The start, blanked as a successor is, and reduced by the tolerance with its own share.
  Outcome start() {
    CompactState state = detail::compact(mdp_->start(), skeletons_);
    detail::blank_hopeless(*mdp_, state);
    Outcome outcome;
    outcome.key = layout_->encode<W>(state);
    if (tolerance_ > 0) {
      find_groups(state);
      for (const Group& group : groups_) {
        if (!tolerated(group, group.spent, group.execution, 0)) continue;
        drop(outcome, group.node, group.refined, group.spent, group.execution, 0);
        clear_members(outcome.key, *group.node);
        blank_members(outcome.key, *group.node);
      }
    }
    return outcome;
  }

 private:
  struct Group {
    const Node* node;  // the next action its members share
    int action;
    int refined;
    std::uint16_t spent, execution;
  };

  void find_groups(const CompactState& state) {
    groups_.clear();
    for (int k = 0; k < skeletons_; ++k) {
      const auto slot = static_cast<std::size_t>(k);
      if (state.spent[slot] == detail::kBlankCounter) continue;
      const int action = mdp_->next_action(state, k);
      if (action < 0) continue;
      const Node& node = tree_->node(action);
      if (node.rep != k) continue;
      groups_.push_back({&node, action, state.refined[slot], state.spent[slot], state.execution[slot]});
    }
  }

  bool tolerated(const Group& group, std::uint16_t spent, std::uint16_t execution, std::int64_t time) const {
    return tolerance_ > 0 && bounds_->group_upper(group.node->rep, group.refined, spent, execution, time) < tolerance_;
  }
  bool tolerated(const Node& node, int refined, std::uint16_t spent, std::uint16_t execution, std::int64_t time) const {
    return tolerance_ > 0 && bounds_->group_upper(node.rep, refined, spent, execution, time) < tolerance_;
  }

  // Notes the share of a group dropped at `time` in the outcome.
  void drop(Outcome& outcome, const Node* node, int refined, std::uint16_t spent, std::uint16_t execution,
            std::int64_t time) const {
    outcome.extras = true;
    outcome.factor *= 1.0 - bounds_->group_upper(node->rep, refined, spent, execution, time);
    for (const int member : tree_->members(*node)) {
      outcome.boost = std::max(outcome.boost, bounds_->commit(member, refined, spent, execution, time));
    }
  }

  void set_members(Key& key, const Node& node, int refined, std::uint16_t spent, std::uint16_t execution) const {
    for (const int member : tree_->members(node)) {
      key.words[static_cast<std::size_t>(layout_->word(member))] |= layout_->value(member, refined, spent, execution);
    }
  }
  void blank_members(Key& key, const Node& node) const {
    for (const int member : tree_->members(node)) {
      key.words[static_cast<std::size_t>(layout_->word(member))] |= layout_->blank(member);
    }
  }
  void clear_members(Key& key, const Node& node) const {
    for (const int member : tree_->members(node)) {
      key.words[static_cast<std::size_t>(layout_->word(member))] &= ~layout_->mask(member);
    }
  }

  template <bool kKeys, class Sink>
  void walk(const Key& key, int t, Sink& sink) {
    layout_->decode(key, t, state_);
    const bool flagged = layout_->flagged(key);
    find_groups(state_);
    const std::int64_t next_time = t + 1;
    const std::int64_t room = std::int64_t{deadline_} - next_time;  // a group needing more is hopeless
    // Per group: alive at the next step (the MDP's test), and kept (alive and not dropped).
    Key base;
    int alive_count = 0;
    if constexpr (kKeys) {
      alive_.assign(groups_.size(), 0);
      kept_.assign(groups_.size(), 0);
      base = key;  // a flagged state's successors stay flagged
      for (std::size_t g = 0; g < groups_.size(); ++g) {
        const Group& group = groups_[g];
        alive_[g] = mdp_->group_need(group.action, group.spent, group.execution) <= room;
        alive_count += alive_[g];
        kept_[g] = alive_[g] && !tolerated(group, group.spent, group.execution, next_time);
        if (!kept_[g]) {
          clear_members(base, *group.node);
          blank_members(base, *group.node);
        }
      }
    }
    for (std::size_t g = 0; g < groups_.size(); ++g) {
      const Group& group = groups_[g];
      const double found = mdp_->hazard(group.action, group.spent);
      Outcome shared;  // what this choice's outcomes have in common: the other groups
      shared.choice = group.node->rep;
      bool others_alive = false, others_kept = false;
      if constexpr (kKeys) {
        shared.key = base;
        clear_members(shared.key, *group.node);
        others_alive = alive_count - alive_[g] > 0;
        for (std::size_t h = 0; h < groups_.size(); ++h) {
          if (h == g || !alive_[h]) continue;
          if (kept_[h]) {
            others_kept = true;
          } else {
            const Group& other = groups_[h];
            drop(shared, other.node, other.refined, other.spent, other.execution, next_time);
          }
        }
      }
      if (found < 1.0) {
        Outcome outcome = shared;
        outcome.probability = 1.0 - found;
        if constexpr (kKeys) missed_outcome(outcome, group, others_alive, others_kept, next_time);
        sink(static_cast<const Outcome&>(outcome));
      }
      if (found > 0.0) {
        for (const Mdp::ExecutionOutcome& execution : mdp_->execution_outcomes(group.action)) {
          Outcome outcome = shared;
          outcome.probability = found * execution.probability;
          if constexpr (kKeys) found_outcome(outcome, group, execution.steps, others_alive, others_kept, next_time);
          sink(static_cast<const Outcome&>(outcome));
        }
      }
    }
    if (split_ && !flagged) {
      Outcome outcome;
      outcome.choice = kWeakChoice;
      outcome.probability = 1.0;
      if constexpr (kKeys) {
        outcome.key = base;
        layout_->set_flag(outcome.key, true);
        bool any_kept = false;
        for (std::size_t h = 0; h < groups_.size(); ++h) {
          if (!alive_[h]) continue;
          if (kept_[h]) {
            any_kept = true;
          } else {
            const Group& other = groups_[h];
            drop(outcome, other.node, other.refined, other.spent, other.execution, next_time);
          }
        }
        finish_running(outcome, alive_count > 0, next_time);
        if (outcome.status == Status::running && !any_kept) outcome.status = Status::failure;
      }
      sink(static_cast<const Outcome&>(outcome));
    }
  }

  // The MDP's own end of an outcome that did not succeed: out of time, or nothing alive.
  void finish_running(Outcome& outcome, bool anything_alive, std::int64_t next_time) const {
    outcome.status = next_time >= deadline_ || !anything_alive ? Status::failure : Status::running;
  }

  // The chosen group's step finds nothing: its PT grows by one.
  void missed_outcome(Outcome& outcome, const Group& group, bool others_alive, bool others_kept,
                      std::int64_t next_time) const {
    const auto spent = static_cast<std::uint16_t>(group.spent + 1);
    const bool alive = mdp_->group_need(group.action, spent, group.execution) <= std::int64_t{deadline_} - next_time;
    finish_running(outcome, alive || others_alive, next_time);
    if (outcome.status != Status::running) return;
    const bool kept = alive && !tolerated(group, spent, group.execution, next_time);
    if (kept) {
      set_members(outcome.key, *group.node, group.refined, spent, group.execution);
    } else {
      blank_members(outcome.key, *group.node);
      if (alive) drop(outcome, group.node, group.refined, spent, group.execution, next_time);
    }
    if (!kept && !others_kept) outcome.status = Status::failure;
  }

  // The chosen group's motion is found with `steps` of execution (deadline + 1: too slow).
  void found_outcome(Outcome& outcome, const Group& group, Steps steps, bool others_alive, bool others_kept,
                     std::int64_t next_time) const {
    const std::int64_t total = std::int64_t{group.execution} + steps;
    const auto execution = static_cast<std::uint16_t>(total > deadline_ ? deadline_ + 1 : total);
    const Node& node = *group.node;
    if (node.completes && next_time + execution <= deadline_) {
      outcome.status = Status::success;
      outcome.extras = false;
      return;
    }
    const std::int64_t room = std::int64_t{deadline_} - next_time;
    const int refined = group.refined + 1;
    // The members move on to the child actions, or end here (too slow: blanked).
    for (const int member : tree_->ending(node)) {
      outcome.key.words[static_cast<std::size_t>(layout_->word(member))] |= layout_->blank(member);
    }
    bool alive_any = false, kept_any = false;
    for (const int child : tree_->children(node)) {
      const Node& next = tree_->node(child);
      const bool alive = mdp_->group_need(child, 0, execution) <= room;
      const bool kept = alive && !tolerated(next, refined, 0, execution, next_time);
      alive_any = alive_any || alive;
      kept_any = kept_any || kept;
      if (kept) {
        set_members(outcome.key, next, refined, 0, execution);
      } else {
        blank_members(outcome.key, next);
        if (alive) drop(outcome, &next, refined, 0, execution, next_time);
      }
    }
    finish_running(outcome, alive_any || others_alive, next_time);
    if (outcome.status == Status::running && !kept_any && !others_kept) outcome.status = Status::failure;
  }

  const Mdp* mdp_;
  const TreeTables* tree_;
  const KeyLayout* layout_;
  const ValueBounds* bounds_;
  double tolerance_;
  bool split_;
  Steps deadline_;
  int skeletons_;
  // Scratch of one walk, kept to avoid allocation per state.
  CompactState state_;
  std::vector<Group> groups_;
  std::vector<char> alive_, kept_;
};

// ---- the search ----

template <std::size_t W>
class LayeredSearch {
 public:
  using Key = PackedState<W>;
  using Outcome = typename Successors<W>::Outcome;

  LayeredSearch(const Mdp& mdp, const LayeredSolveOptions& options, const KeyLayout& layout, const ValueBounds* bounds,
                const WeakCluster* weak)
      : mdp_(&mdp),
        tree_(mdp.problem()),
        options_(&options),
        layout_(&layout),
        bounds_(bounds),
        weak_(weak),
        rank_(options.ranks != nullptr ? options.ranks->rank() : 0),
        ranks_(options.ranks != nullptr ? options.ranks->size() : 1),
        threads_(worker_count(std::numeric_limits<std::uint64_t>::max(), options.threads)),
        shard_bits_(static_cast<int>(std::bit_width(std::bit_ceil(threads_) - 1))),
        shards_(std::size_t{1} << shard_bits_),
        scratch_(options.scratch_directory, rank_, options.remove_scratch_on_signal, options.on_stale_scratch) {}

  LayeredSolution run() {
    solution_.key_bytes = sizeof(Key);
    Successors<W> successors(*mdp_, tree_, *layout_, bounds_, options_->tolerance, weak_ != nullptr);
    start_ = successors.start();
    if (start_.extras) ++dropped_;
    std::vector<Key> current;
    if (owner_of(start_.key) == rank_) current.push_back(start_.key);
    current = forward(std::move(current));
    backward(std::move(current));
    finish();
    return std::move(solution_);
  }

 private:
  // One layer's places: shard s holds its keys in the order they were found; a state's place in
  // the layer is base[s] + its index in the shard.
  struct LayerPlaces {
    std::vector<std::uint64_t> base;  // shards_ + 1 offsets
  };

  // What the forward pass leaves for the backward pass, per layer.
  struct LayerRecord {
    std::uint64_t states = 0;           // this rank's
    std::vector<std::uint64_t> blocks;  // per block of kBlock states: codes then extras in its part of the files
    std::vector<std::vector<std::uint32_t>> foreign;  // per rank: the codes (in the owner's layer t + 1) asked for
    std::vector<std::uint16_t> foreign_rank;          // per foreign entry, in the order numbered: its owner
    LayerPlaces next;                                 // places of layer t + 1 (this rank's)
  };

  int owner_of(const Key& key) const noexcept {
    return ranks_ == 1 ? 0 : static_cast<int>((placement_hash(key) >> 40) % static_cast<std::uint64_t>(ranks_));
  }
  std::size_t shard_of(const Key& key) const noexcept {
    return static_cast<std::size_t>(placement_hash(key) & (shards_ - 1));
  }

  // ---- forward: enumerate the layers ----

  std::vector<Key> forward(std::vector<Key> current) {
    for (int t = 0;; ++t) {
      const std::uint64_t states = sum_over_ranks(current.size());
      solution_.layers.push_back({.layer = t, .states = states});
      solution_.states += states;
      top_ = t;
      const auto started = Clock::now();
      Cut cut = Cut::none;
      if (options_->stop && options_->stop()) cut = Cut::stop;
      // A layer left behind costs its keys and at least one code per state on disk.
      if (options_->max_disk_bytes != 0 &&
          disk_bytes_ + current.size() * (sizeof(Key) + sizeof(std::uint32_t)) > options_->max_disk_bytes) {
        cut = Cut::disk;
      }
      cut = first_cut(cut);
      std::vector<Key> next;
      if (cut == Cut::none) {
        records_.emplace_back();
        cut = expand(current, t, next);
      }
      std::uint64_t next_states = 0;
      if (cut == Cut::none) {
        next_states = sum_over_ranks(next.size());
        if (options_->max_states != 0 && solution_.states + next_states > options_->max_states) cut = Cut::states;
        cut = first_cut(cut);
      }
      if (cut != Cut::none) {
        // Layer t gets bounds instead of values: what its expansion wrote goes.
        if (records_.size() > static_cast<std::size_t>(t)) records_.pop_back();
        remove_layer_files(t);
        frontier_ = t;
        solution_.stopped_by = describe(cut, t);
        report(solution_.layers.back());
        return current;
      }
      solution_.layers.back().forward_seconds = seconds_since(started);
      report(solution_.layers.back());
      if (next_states == 0) return current;  // every successor of layer t ends the episode
      write_keys(t, current);
      current = std::move(next);
    }
  }

  // Per thread, per chunk: the codes and extras of the blocks it took, and the successors it
  // found, by the shard (own) or rank (foreign) they belong to, with where their codes go.
  struct Pending {
    Key key;
    std::uint32_t block;  // within the chunk
    std::uint32_t at;     // index of its code within the block's codes
  };
  // Each on cache lines of its own: threads filling neighbouring ones must not share lines.
  struct alignas(64) BlockOutput {
    std::vector<std::uint32_t> codes;
    std::vector<double> extras;
  };
  struct alignas(64) PendingList {
    std::vector<Pending> list;
  };
  struct alignas(64) ThreadBuffers {
    std::vector<PendingList> own;      // per shard
    std::vector<PendingList> foreign;  // per rank
  };

  // Builds layer t + 1 from this rank's states of layer t, writing layer t's codes; returns a
  // cut if a cap ended it (every rank agrees).
  Cut expand(const std::vector<Key>& current, int t, std::vector<Key>& next) {
    LayerRecord& record = records_.back();
    record.states = current.size();
    record.foreign.assign(static_cast<std::size_t>(ranks_), {});
    const std::uint64_t block_count = (current.size() + kBlock - 1) / kBlock;
    record.blocks.assign(2 * block_count, 0);
    // What this layer's expansion holds: this layer's keys, then the tables as they grow, the
    // chunk's buffers and, over ranks, the foreign entries.
    MemoryBudget budget(options_->max_memory_bytes);
    budget.take(current.capacity() * sizeof(Key));
    std::uint64_t buffer_bytes = 0;
    std::vector<PlaceTable<W>> tables(shards_);
    // Foreign successors met so far in this layer: (owner, code there) -> entry of record.foreign.
    absl::flat_hash_map<std::uint64_t, std::uint32_t> foreign_entries;
    std::uint32_t foreign_count = 0;
    ScratchFile codes_file(scratch_.file(t, "codes"), t, "wb");
    ScratchFile extras_file(scratch_.file(t, "extras"), t, "wb");
    std::vector<ThreadBuffers> buffers(threads_);
    for (ThreadBuffers& buffer : buffers) {
      buffer.own.resize(shards_);
      buffer.foreign.resize(static_cast<std::size_t>(ranks_));
    }
    std::vector<BlockOutput> blocks(kChunkBlocks);
    const std::uint64_t chunks = max_over_ranks((current.size() + kChunk - 1) / kChunk);
    for (std::uint64_t chunk = 0; chunk < chunks; ++chunk) {
      const std::uint64_t begin = std::min<std::uint64_t>(current.size(), chunk * kChunk);
      const std::uint64_t end = std::min<std::uint64_t>(current.size(), begin + kChunk);
      const std::uint64_t chunk_blocks = (end - begin + kBlock - 1) / kBlock;
      // Phase 1: outcomes and successor keys, block by block.
      for_each_block(chunk_blocks, options_->threads, 1, [&](unsigned thread) {
        return [&, thread,
                successors = Successors<W>(*mdp_, tree_, *layout_, bounds_, options_->tolerance, weak_ != nullptr)](
                   std::uint64_t b, std::uint64_t) mutable {
          ThreadBuffers& buffer = buffers[thread];
          BlockOutput& output = blocks[b];
          output.codes.clear();
          output.extras.clear();
          const std::uint64_t first = begin + b * kBlock;
          const std::uint64_t last = std::min(end, first + kBlock);
          std::uint64_t dropped = 0;
          const auto sink = [&](const Outcome& outcome) {
            if (outcome.extras) {
              output.codes.push_back(kExtrasCode);
              output.extras.push_back(outcome.factor);
              output.extras.push_back(outcome.boost);
              ++dropped;
            }
            if (outcome.status != Status::running) {
              output.codes.push_back(outcome.status == Status::success ? kSuccessCode : kFailureCode);
              return;
            }
            const Pending pending{outcome.key, static_cast<std::uint32_t>(b),
                                  static_cast<std::uint32_t>(output.codes.size())};
            output.codes.push_back(0);
            const int owner = owner_of(outcome.key);
            if (owner == rank_) {
              buffer.own[shard_of(outcome.key)].list.push_back(pending);
            } else {
              buffer.foreign[static_cast<std::size_t>(owner)].list.push_back(pending);
            }
          };
          for (std::uint64_t i = first; i < last; ++i) successors.expand(current[i], t, sink);
          dropped_counter_.fetch_add(dropped, std::memory_order_relaxed);
        };
      });
      // Successors owned by other ranks: their keys go to the owners, which answer with codes.
      std::vector<std::string> asked;
      if (ranks_ > 1) {
        std::vector<std::string> parts(static_cast<std::size_t>(ranks_));
        for (std::size_t r = 0; r < parts.size(); ++r) {
          for (const ThreadBuffers& buffer : buffers) {
            for (const Pending& pending : buffer.foreign[r].list) {
              parts[r].append(reinterpret_cast<const char*>(pending.key.words.data()), sizeof(Key));
            }
          }
        }
        asked = options_->ranks->all_to_all(parts);
      }
      // Phase 2: each shard's thread places its successors (own, then asked by other ranks).
      std::vector<std::string> answers(static_cast<std::size_t>(ranks_));
      for (std::size_t r = 0; r < answers.size(); ++r)
        answers[r].resize(asked.empty() ? 0 : asked[r].size() / sizeof(Key) * sizeof(std::uint32_t));
      std::atomic<bool> overflow{false}, out_of_memory{false};
      for_each_block(shards_, options_->threads, 1, [&](unsigned) {
        return [&](std::uint64_t s, std::uint64_t) {
          auto& table = tables[s];
          const auto place = [&](const Key& key, std::uint64_t hash) -> std::uint32_t {
            std::uint32_t index = 0;
            if (out_of_memory || !table.place(key, hash, budget, index)) {
              out_of_memory = true;  // the layer is cut: the codes no longer matter
              return 0;
            }
            const std::uint64_t code = std::uint64_t{index} << shard_bits_ | s;
            if (code >= kForeignBase) overflow = true;
            return static_cast<std::uint32_t>(code);
          };
          for (ThreadBuffers& buffer : buffers) {
            // The table is far larger than the caches: its slots are fetched a few keys ahead,
            // so that the misses overlap.
            const std::vector<Pending>& pending = buffer.own[s].list;
            for (std::size_t i = 0; i < std::min(pending.size(), kPrefetchAhead); ++i) {
              table.prefetch(PlaceTable<W>::hash(pending[i].key));
            }
            for (std::size_t i = 0; i < pending.size(); ++i) {
              if (i + kPrefetchAhead < pending.size())
                table.prefetch(PlaceTable<W>::hash(pending[i + kPrefetchAhead].key));
              blocks[pending[i].block].codes[pending[i].at] =
                  place(pending[i].key, PlaceTable<W>::hash(pending[i].key));
            }
            buffer.own[s].list.clear();
          }
          for (std::size_t r = 0; r < asked.size(); ++r) {
            const std::string& keys_asked = asked[r];
            for (std::size_t i = 0; i < keys_asked.size() / sizeof(Key); ++i) {
              Key key;
              std::memcpy(key.words.data(), keys_asked.data() + i * sizeof(Key), sizeof(Key));
              if (shard_of(key) != s) continue;
              const std::uint32_t code = place(key, PlaceTable<W>::hash(key));
              std::memcpy(answers[r].data() + i * sizeof(std::uint32_t), &code, sizeof(code));
            }
          }
        };
      });
      if (overflow && !out_of_memory) {
        throw ResourceLimitError("layer " + std::to_string(t + 1) + ": more states than one rank can index (" +
                                 std::to_string(kForeignBase >> shard_bits_) +
                                 " per thread); split the work over more ranks");
      }
      if (ranks_ > 1) {
        const std::vector<std::string> replies = options_->ranks->all_to_all(answers);
        for (std::size_t r = 0; r < replies.size(); ++r) {
          std::size_t i = 0;
          for (ThreadBuffers& buffer : buffers) {
            for (const Pending& pending : buffer.foreign[r].list) {
              std::uint32_t code = 0;
              std::memcpy(&code, replies[r].data() + i * sizeof(code), sizeof(code));
              ++i;
              const auto [where, inserted] =
                  foreign_entries.try_emplace(static_cast<std::uint64_t>(r) << 32 | code, foreign_count);
              if (inserted) {
                record.foreign[r].push_back(code);
                record.foreign_rank.push_back(static_cast<std::uint16_t>(r));
                ++foreign_count;
              }
              if (foreign_count >= kSpecialBase - kForeignBase) {
                throw ResourceLimitError("layer " + std::to_string(t + 1) +
                                         ": more successors owned by other ranks than one rank can index");
              }
              blocks[pending.block].codes[pending.at] = kForeignBase + where->second;
            }
            buffer.foreign[r].list.clear();
          }
        }
      }
      // Caps, agreed by every rank at the end of each chunk.
      std::uint64_t chunk_bytes = foreign_entries.capacity() * (sizeof(std::uint64_t) + sizeof(std::uint32_t) + 1);
      for (const BlockOutput& block : blocks) chunk_bytes += block.codes.capacity() * 4 + block.extras.capacity() * 8;
      for (const ThreadBuffers& buffer : buffers) {
        for (const PendingList& list : buffer.own) chunk_bytes += list.list.capacity() * sizeof(Pending);
        for (const PendingList& list : buffer.foreign) chunk_bytes += list.list.capacity() * sizeof(Pending);
      }
      if (chunk_bytes > buffer_bytes && !budget.take(chunk_bytes - buffer_bytes)) out_of_memory = true;
      buffer_bytes = std::max(buffer_bytes, chunk_bytes);
      note_memory(budget.held());
      Cut cut = Cut::none;
      if (out_of_memory) cut = Cut::memory;
      if (options_->stop && options_->stop()) cut = Cut::stop;
      std::uint64_t chunk_disk = 0;
      for (std::uint64_t b = 0; b < chunk_blocks; ++b) {
        chunk_disk += blocks[b].codes.size() * sizeof(std::uint32_t) + blocks[b].extras.size() * sizeof(double);
      }
      if (options_->max_disk_bytes != 0 && disk_bytes_ + chunk_disk > options_->max_disk_bytes) cut = Cut::disk;
      if (options_->max_states != 0) {
        // The next layer already passes the state cap: no need to build the rest of it.
        std::uint64_t found = 0;
        for (const PlaceTable<W>& table : tables) found += table.keys().size();
        if (solution_.states + sum_over_ranks(found) > options_->max_states) cut = Cut::states;
      }
      cut = first_cut(cut);
      if (cut != Cut::none) return cut;
      // The chunk's codes, block by block, to the layer's files.
      for (std::uint64_t b = 0; b < chunk_blocks; ++b) {
        const std::uint64_t index = begin / kBlock + b;
        record.blocks[2 * index] = blocks[b].codes.size();
        record.blocks[2 * index + 1] = blocks[b].extras.size();
        codes_file.write(blocks[b].codes.data(), blocks[b].codes.size());
        extras_file.write(blocks[b].extras.data(), blocks[b].extras.size());
      }
      disk_bytes_ += chunk_disk;
      solution_.peak_disk_bytes = std::max(solution_.peak_disk_bytes, disk_bytes_);
    }
    codes_file.close();
    extras_file.close();
    // The next layer: the shards' keys one after the other. The backward pass will hold this
    // layer's keys, values and choices and the next layer's values.
    std::uint64_t total = 0;
    for (const PlaceTable<W>& table : tables) total += table.keys().size();
    const std::uint64_t backward_bytes =
        current.size() * (sizeof(Key) + sizeof(Bounds) + sizeof(int)) + total * sizeof(Bounds);
    note_memory(backward_bytes);
    Cut cut = Cut::none;
    if (!budget.take(total * sizeof(Key)) ||
        (options_->max_memory_bytes != 0 && backward_bytes > options_->max_memory_bytes)) {
      cut = Cut::memory;
    }
    cut = first_cut(cut);
    if (cut != Cut::none) return cut;
    note_memory(budget.held());
    record.next.base.assign(shards_ + 1, 0);
    next.clear();
    next.reserve(total);
    for (std::size_t s = 0; s < shards_; ++s) {
      record.next.base[s] = next.size();
      next.insert(next.end(), tables[s].keys().begin(), tables[s].keys().end());
      tables[s].clear(budget);
    }
    record.next.base[shards_] = next.size();
    return Cut::none;
  }

  void write_keys(int t, const std::vector<Key>& keys) {
    ScratchFile file(scratch_.file(t, "keys"), t, "wb");
    file.write(keys.data(), keys.size());
    file.close();
    disk_bytes_ += keys.size() * sizeof(Key);
    solution_.peak_disk_bytes = std::max(solution_.peak_disk_bytes, disk_bytes_);
  }

  template <class T>
  std::vector<T> read_file(int t, const char* what, std::size_t count) {
    std::vector<T> data(count);
    ScratchFile file(scratch_.file(t, what), t, "rb");
    file.read(data.data(), count);
    return data;
  }

  void remove_layer_files(int t) {
    for (const char* what : {"keys", "codes", "extras"}) {
      std::error_code error;
      const std::filesystem::path path = scratch_.file(t, what);
      const auto bytes = std::filesystem::file_size(path, error);
      if (!error) disk_bytes_ -= std::min<std::uint64_t>(disk_bytes_, bytes);
      std::filesystem::remove(path, error);
    }
  }

  // ---- backward: value the layers from the last to the first ----

  void backward(std::vector<Key> top_keys) {
    std::vector<Bounds> next_values;  // layer t + 1, by place
    for (int t = top_; t >= 0; --t) {
      const auto started = Clock::now();
      std::vector<Key> keys;
      if (t == top_) {
        keys = std::exchange(top_keys, {});
      } else {
        keys = read_file<Key>(t, "keys", records_[static_cast<std::size_t>(t)].states);
      }
      std::vector<Bounds> values(keys.size());
      std::vector<int> choices(keys.size(), -1);
      if (t == frontier_) {
        value_frontier(keys, t, values, choices);
      } else {
        value_layer(keys, t, next_values, values, choices);
      }
      if (t < options_->policy_layers) keep_policy(keys, values, choices, t);
      if (t == 0 && !keys.empty()) {
        start_value_ = values[0];
        start_choice_ = choices[0];
        has_start_ = true;
      }
      note_memory(keys.size() * (sizeof(Key) + sizeof(Bounds) + sizeof(int)) + next_values.size() * sizeof(Bounds));
      next_values = std::move(values);
      remove_layer_files(t);
      LayerFigures& figures = solution_.layers[static_cast<std::size_t>(t)];
      figures.backward_seconds = seconds_since(started);
      figures.backward = true;
      report(figures);
    }
  }

  void value_frontier(const std::vector<Key>& keys, int t, std::vector<Bounds>& values, std::vector<int>& choices) {
    std::optional<ValueBounds> own;
    const ValueBounds* bounds = bounds_;
    if (bounds == nullptr) {
      try {
        own.emplace(*mdp_);
        bounds = &*own;
      } catch (const ResourceLimitError&) {
        // Tables too large for this deadline: the frontier gets the trivial bounds [0, 1].
      }
    }
    for_each_block(keys.size(), options_->threads, kBlock, [&](unsigned) {
      return [&](std::uint64_t begin, std::uint64_t end) {
        CompactState state;
        for (std::uint64_t i = begin; i < end; ++i) {
          layout_->decode(keys[i], t, state);
          if (bounds != nullptr) {
            values[i] = {bounds->lower(state), bounds->upper(state)};
            choices[i] = bounds->lower_choice(state);
          } else {
            values[i] = {0.0, mdp_->any_can_succeed(state) ? 1.0 : 0.0};
          }
          if (weak_ != nullptr && !layout_->flagged(keys[i])) {
            // The bounded subtrees, fresh: committing to them is a policy; above, the two parts
            // as if each had all the time left.
            const auto at = static_cast<std::size_t>(t);
            if (weak_->lower[at] > values[i].lower) {
              values[i].lower = weak_->lower[at];
              choices[i] = kWeakChoice;
            }
            values[i].upper = 1.0 - (1.0 - values[i].upper) * (1.0 - weak_->upper[at]);
          }
        }
      };
    });
  }

  void value_layer(const std::vector<Key>& keys, int t, const std::vector<Bounds>& next_values,
                   std::vector<Bounds>& values, std::vector<int>& choices) {
    const LayerRecord& record = records_[static_cast<std::size_t>(t)];
    const std::vector<Bounds> foreign = fetch_foreign_values(record, next_values);
    // Where each block's codes and extras start in the layer's files.
    const std::size_t block_count = record.blocks.size() / 2;
    std::vector<std::uint64_t> code_start(block_count + 1, 0), extra_start(block_count + 1, 0);
    for (std::size_t b = 0; b < block_count; ++b) {
      code_start[b + 1] = code_start[b] + record.blocks[2 * b];
      extra_start[b + 1] = extra_start[b] + record.blocks[2 * b + 1];
    }
    ScratchFile codes_file(scratch_.file(t, "codes"), t, "rb");
    ScratchFile extras_file(scratch_.file(t, "extras"), t, "rb");
    std::vector<std::uint32_t> codes;
    std::vector<double> extras;
    for (std::size_t first_block = 0; first_block < block_count; first_block += kChunkBlocks) {
      const std::size_t last_block = std::min(block_count, first_block + kChunkBlocks);
      codes.resize(code_start[last_block] - code_start[first_block]);
      extras.resize(extra_start[last_block] - extra_start[first_block]);
      codes_file.read(codes.data(), codes.size());
      extras_file.read(extras.data(), extras.size());
      for_each_block(last_block - first_block, options_->threads, 1, [&](unsigned) {
        return [&, successors = Successors<W>(*mdp_, tree_, *layout_, bounds_, options_->tolerance, weak_ != nullptr)](
                   std::uint64_t b, std::uint64_t) mutable {
          const std::size_t block = first_block + b;
          StateValue value(this, t, record.next, next_values, foreign);
          value.code = codes.data() + (code_start[block] - code_start[first_block]);
          value.extra = extras.data() + (extra_start[block] - extra_start[first_block]);
          const std::uint64_t end = std::min<std::uint64_t>(keys.size(), (block + 1) * kBlock);
          for (std::uint64_t i = block * kBlock; i < end; ++i) {
            value.begin(layout_->flagged(keys[i]));
            successors.probabilities(keys[i], t, value);
            values[i] = value.end(choices[i]);
          }
        };
      });
    }
  }

  // V (or its bounds) of one state after another, fed their outcomes in order and reading their
  // codes: the same sums in the same order, and the same tie rule, as the memoised solver.
  struct StateValue {
    StateValue(const LayeredSearch* search_, int t_, const LayerPlaces& places_,
               const std::vector<Bounds>& next_values_, const std::vector<Bounds>& foreign_)
        : search(search_), t(t_), places(places_), next_values(next_values_), foreign(foreign_) {}
    const LayeredSearch* search;
    int t;
    const LayerPlaces& places;
    const std::vector<Bounds>& next_values;
    const std::vector<Bounds>& foreign;
    const std::uint32_t* code = nullptr;
    const double* extra = nullptr;
    // What the end of the enumerated part is worth: nothing, or in a split's unflagged states
    // the bounded subtrees, fresh, with the time left.
    Bounds ended;
    int candidate = 0;
    bool any = false;
    double lower_sum = 0, upper_sum = 0;
    double best_lower = -1.0, best_upper = 0.0, lower_of_best = 0.0;
    int choice = -1;

    void begin(bool flagged) {
      const WeakCluster* weak = search->weak_;
      const auto next_t = static_cast<std::size_t>(t) + 1;
      ended = weak != nullptr && !flagged ? Bounds{weak->lower[next_t], weak->upper[next_t]} : Bounds{};
      any = false;
      best_lower = -1.0;
      best_upper = 0.0;
      lower_of_best = 0.0;
      choice = -1;
    }

    void close_choice() {
      if (lower_sum > best_lower + OptimalSolver::kTieTolerance) {
        best_lower = lower_sum;
        lower_of_best = lower_sum;
        choice = candidate;
      }
      best_upper = std::max(best_upper, upper_sum);
    }

    void operator()(const Outcome& outcome) {
      if (!any || outcome.choice != candidate) {
        if (any) close_choice();
        any = true;
        candidate = outcome.choice;
        lower_sum = 0.0;
        upper_sum = 0.0;
      }
      const double probability = outcome.probability;
      bool has_extras = false;
      double factor = 1.0, boost = 0.0;
      if (*code == kExtrasCode) {
        has_extras = true;
        factor = extra[0];
        boost = extra[1];
        extra += 2;
        ++code;
      }
      const std::uint32_t at = *code++;
      if (at == kSuccessCode) {
        lower_sum += probability;
        upper_sum += probability;
        return;
      }
      if (at == kFailureCode && !has_extras && candidate != kWeakChoice && ended.upper == 0.0) {
        return;  // worth nothing, and the memoised solver adds nothing for it either
      }
      // A failure leaves the bounded subtrees (if any); after a step on them, the enumerated
      // part alone.
      Bounds value = candidate == kWeakChoice ? Bounds{} : ended;
      if (at != kFailureCode) {
        value = at >= kForeignBase ? foreign[at - kForeignBase]
                                   : next_values[places.base[at & (search->shards_ - 1)] + (at >> search->shard_bits_)];
      }
      if (has_extras) value = {std::max(value.lower, boost), 1.0 - (1.0 - value.upper) * factor};
      if (candidate == kWeakChoice) {
        const WeakCluster* weak = search->weak_;
        const auto now = static_cast<std::size_t>(t);
        value = {std::max(value.lower, weak->lower[now]), 1.0 - (1.0 - value.upper) * (1.0 - weak->upper[now])};
      }
      lower_sum += probability * value.lower;
      upper_sum += probability * value.upper;
    }

    Bounds end(int& chosen) {
      if (any) close_choice();
      chosen = choice;
      return {lower_of_best, best_upper};
    }
  };

  // Over ranks: the values of the successors this rank's states of layer t have on other ranks.
  std::vector<Bounds> fetch_foreign_values(const LayerRecord& record, const std::vector<Bounds>& next_values) {
    if (ranks_ == 1) return {};
    std::vector<std::string> requests(static_cast<std::size_t>(ranks_));
    for (std::size_t r = 0; r < requests.size(); ++r) {
      requests[r].assign(reinterpret_cast<const char*>(record.foreign[r].data()),
                         record.foreign[r].size() * sizeof(std::uint32_t));
    }
    std::vector<std::string> answers;
    for (const std::string& request : options_->ranks->all_to_all(requests)) {
      std::string answer(request.size() / sizeof(std::uint32_t) * sizeof(Bounds), '\0');
      for (std::size_t i = 0; i < request.size() / sizeof(std::uint32_t); ++i) {
        std::uint32_t at = 0;
        std::memcpy(&at, request.data() + i * sizeof(at), sizeof(at));
        const Bounds value = next_values[record.next.base[at & (shards_ - 1)] + (at >> shard_bits_)];
        std::memcpy(answer.data() + i * sizeof(Bounds), &value, sizeof(Bounds));
      }
      answers.push_back(std::move(answer));
    }
    const std::vector<std::string> replies = options_->ranks->all_to_all(answers);
    // Entries were numbered in the order they were first met, owners interleaved: each owner's
    // answers come in its list's order.
    std::vector<Bounds> values;
    values.reserve(record.foreign_rank.size());
    std::vector<std::size_t> next(static_cast<std::size_t>(ranks_), 0);
    for (const std::uint16_t owner : record.foreign_rank) {
      const std::size_t r = owner;
      Bounds value;
      std::memcpy(&value, replies[r].data() + next[r] * sizeof(Bounds), sizeof(Bounds));
      ++next[r];
      values.push_back(value);
    }
    return values;
  }

  void keep_policy(const std::vector<Key>& keys, const std::vector<Bounds>& values, const std::vector<int>& choices,
                   int t) {
    for (std::size_t i = 0; i < keys.size(); ++i) {
      if (layout_->flagged(keys[i])) continue;  // copies a split counts, not states of the problem
      policy_.push_back({t, keys[i], choices[i], values[i]});
    }
  }

  // ---- results, shared by every rank ----

  void finish() {
    const std::uint64_t dropped = sum_over_ranks(dropped_counter_.load() + dropped_);
    solution_.dropped = dropped;
    const bool exact = frontier_ < 0 && dropped == 0 && weak_ == nullptr;
    solution_.peak_memory_bytes = peak_memory_.load();
    BytePacker packer;
    packer.put(static_cast<std::uint8_t>(has_start_));
    packer.put(start_value_.lower);
    packer.put(start_value_.upper);
    packer.put(start_choice_);
    packer.put(solution_.peak_memory_bytes);
    packer.put(solution_.peak_disk_bytes);
    packer.put(static_cast<std::uint64_t>(policy_.size()));
    for (const PolicyRecord& record : policy_) {
      packer.put(record.layer);
      packer.put(record.key);
      packer.put(record.choice);
      packer.put(record.value);
    }
    std::vector<PolicyRecord> policy;
    for (const std::string& part : gather(packer.bytes())) {
      ByteUnpacker unpacker(part);
      const bool has = unpacker.get<std::uint8_t>() != 0;
      const auto lower = unpacker.get<double>();
      const auto upper = unpacker.get<double>();
      const auto choice = unpacker.get<int>();
      if (has) {
        solution_.lower = lower;
        solution_.upper = upper;
        solution_.first_choice = choice;
      }
      solution_.peak_memory_bytes = std::max(solution_.peak_memory_bytes, unpacker.get<std::uint64_t>());
      solution_.peak_disk_bytes = std::max(solution_.peak_disk_bytes, unpacker.get<std::uint64_t>());
      const auto count = unpacker.get<std::uint64_t>();
      for (std::uint64_t i = 0; i < count; ++i) {
        PolicyRecord record;
        record.layer = unpacker.get<int>();
        record.key = unpacker.get<Key>();
        record.choice = unpacker.get<int>();
        record.value = unpacker.get<Bounds>();
        policy.push_back(record);
      }
    }
    // The start's own dropped groups.
    if (start_.extras) {
      solution_.lower = std::max(solution_.lower, start_.boost);
      solution_.upper = 1.0 - (1.0 - solution_.upper) * start_.factor;
    }
    if (exact) solution_.upper = solution_.lower;
    solution_.exact = exact;
    solution_.frontier_layer = frontier_;
    std::sort(policy.begin(), policy.end(), [](const PolicyRecord& a, const PolicyRecord& b) {
      return a.layer != b.layer ? a.layer < b.layer : a.key.words < b.key.words;
    });
    for (const PolicyRecord& record : policy) {
      CompactState compact;
      layout_->decode(record.key, record.layer, compact);
      State state(static_cast<std::size_t>(mdp_->skeleton_count()));
      detail::expanded(compact, state);
      solution_.policy.push_back(
          {std::move(state), record.choice, record.value.lower, exact ? record.value.lower : record.value.upper});
    }
  }

  struct PolicyRecord {
    int layer = 0;
    Key key;
    int choice = -1;
    Bounds value;
  };

  // ---- exchanges between ranks (no-ops for one process) ----

  std::vector<std::string> gather(const std::string& bytes) const {
    return ranks_ == 1 ? std::vector<std::string>{bytes} : options_->ranks->all_gather(bytes);
  }

  std::uint64_t sum_over_ranks(std::uint64_t count) const {
    if (ranks_ == 1) return count;
    BytePacker packer;
    packer.put(count);
    std::uint64_t total = 0;
    for (const std::string& part : gather(packer.bytes())) total += ByteUnpacker(part).get<std::uint64_t>();
    return total;
  }

  std::uint64_t max_over_ranks(std::uint64_t count) const {
    if (ranks_ == 1) return count;
    BytePacker packer;
    packer.put(count);
    std::uint64_t most = 0;
    for (const std::string& part : gather(packer.bytes()))
      most = std::max(most, ByteUnpacker(part).get<std::uint64_t>());
    return most;
  }

  // The first rank's reason to cut, if any rank has one (every rank must call it).
  Cut first_cut(Cut mine) const {
    if (ranks_ == 1) return mine;
    BytePacker packer;
    packer.put(static_cast<std::uint8_t>(mine));
    for (const std::string& part : gather(packer.bytes())) {
      const auto cut = static_cast<Cut>(ByteUnpacker(part).get<std::uint8_t>());
      if (cut != Cut::none) return cut;
    }
    return Cut::none;
  }

  void note_memory(std::uint64_t bytes) {
    std::uint64_t seen = peak_memory_.load(std::memory_order_relaxed);
    while (bytes > seen && !peak_memory_.compare_exchange_weak(seen, bytes)) {
    }
  }

  std::string describe(Cut cut, int t) const {
    std::string at =
        "the forward pass stopped at layer " + std::to_string(t) + " (" + std::to_string(solution_.states) + " states)";
    switch (cut) {
      case Cut::stop:
        return at + " at the caller's request";
      case Cut::states:
        return at + ": the next layer would pass the cap of " + std::to_string(options_->max_states) + " states";
      case Cut::memory:
        return at + ": the next layer would pass the memory cap of " +
               std::to_string(options_->max_memory_bytes >> 20) + " MiB";
      case Cut::disk:
        return at + ": its scratch files would pass the disk cap of " + std::to_string(options_->max_disk_bytes >> 20) +
               " MiB";
      case Cut::none:
        break;
    }
    return at;
  }

  void report(const LayerFigures& figures) const {
    if (options_->on_layer) options_->on_layer(figures);
  }

  // States per block (a thread's unit of work, and the unit of the files' index) and blocks per
  // chunk (between two exchanges and cap checks).
  static constexpr std::uint64_t kBlock = 2048;
  static constexpr std::uint64_t kChunkBlocks = 64;
  static constexpr std::uint64_t kChunk = kBlock * kChunkBlocks;
  // How far ahead of its insertion a successor's table slot is prefetched.
  static constexpr std::size_t kPrefetchAhead = 32;

  const Mdp* mdp_;
  TreeTables tree_;
  const LayeredSolveOptions* options_;
  const KeyLayout* layout_;
  const ValueBounds* bounds_;
  const WeakCluster* weak_;
  int rank_;
  int ranks_;
  unsigned threads_;
  int shard_bits_;
  std::size_t shards_;
  ScratchDirectory scratch_;
  LayeredSolution solution_;
  std::vector<LayerRecord> records_;
  std::atomic<std::uint64_t> peak_memory_{0};
  std::atomic<std::uint64_t> dropped_counter_{0};
  std::uint64_t dropped_ = 0;
  std::uint64_t disk_bytes_ = 0;
  int top_ = 0;        // the last layer enumerated
  int frontier_ = -1;  // the layer that gets bounds, when cut
  Outcome start_;
  Bounds start_value_;
  int start_choice_ = -1;
  bool has_start_ = false;
  std::vector<PolicyRecord> policy_;
};

}  // namespace

namespace {

// The skeletons under each first action, in order of their first action's first skeleton.
std::vector<std::vector<int>> root_subtrees(const Problem& problem) {
  std::vector<std::vector<int>> subtrees;
  std::vector<int> root_of(static_cast<std::size_t>(problem.action_count()), -1);
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    int& index = root_of[static_cast<std::size_t>(problem.action_at(k, 0))];
    if (index < 0) {
      index = static_cast<int>(subtrees.size());
      subtrees.emplace_back();
    }
    subtrees[static_cast<std::size_t>(index)].push_back(k);
  }
  return subtrees;
}

Problem subproblem(const Problem& problem, const std::vector<int>& skeletons, const std::string& part) {
  std::vector<Action> actions(problem.actions().begin(), problem.actions().end());
  std::vector<std::vector<int>> paths;
  for (const int k : skeletons) {
    const auto path = problem.skeleton(k);
    paths.emplace_back(path.begin(), path.end());
  }
  return Problem(problem.name() + " (" + part + ")", problem.deadline(), problem.step_seconds(), std::move(actions),
                 std::move(paths));
}

template <std::size_t W>
LayeredSolution run_search(const Mdp& mdp, const LayeredSolveOptions& options, bool flag, const WeakCluster* weak) {
  const KeyLayout layout(mdp, flag);
  std::optional<ValueBounds> bounds;
  if (options.tolerance > 0) bounds.emplace(mdp);  // ResourceLimitError when the tables are too large
  return LayeredSearch<W>(mdp, options, layout, bounds ? &*bounds : nullptr, weak).run();
}

LayeredSolution dispatch(const Mdp& mdp, const LayeredSolveOptions& options, bool flag, const WeakCluster* weak) {
  const int words = KeyLayout(mdp, flag).words();
  if (words <= 1) return run_search<1>(mdp, options, flag, weak);
  if (words <= 2) return run_search<2>(mdp, options, flag, weak);
  if (words <= 4) return run_search<4>(mdp, options, flag, weak);
  if (words <= kMaxExactSkeletons) return run_search<kMaxExactSkeletons>(mdp, options, flag, weak);
  return run_search<kMaxExactSkeletons + 1>(mdp, options, flag, weak);  // a split's flag past 16 words
}

}  // namespace

std::vector<int> split_plan(const Mdp& mdp) {
  const std::vector<std::vector<int>> subtrees = root_subtrees(mdp.problem());
  if (subtrees.size() < 2) return {};
  const ValueBounds bounds(mdp);
  const State start = mdp.start();
  std::size_t best = 0;
  double best_chance = -1.0;
  for (std::size_t i = 0; i < subtrees.size(); ++i) {
    const int k = subtrees[i].front();
    const double chance = bounds.group_upper(k, 0, 0, 0, start.time);
    if (chance > best_chance) {
      best_chance = chance;
      best = i;
    }
  }
  return subtrees[best];
}

namespace {

LayeredSolution solve_split(const Mdp& mdp, const LayeredSolveOptions& options, const std::vector<int>& kept) {
  const Problem& problem = mdp.problem();
  std::vector<int> bounded;
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    if (!std::binary_search(kept.begin(), kept.end(), k)) bounded.push_back(k);
  }
  const Problem strong = subproblem(problem, kept, "enumerated part");
  const Problem others = subproblem(problem, bounded, "bounded part");
  const Mdp strong_mdp(strong);
  const Mdp others_mdp(others);
  // The bounded subtrees, fresh, from every CT: their best commit and their clairvoyant chance.
  WeakCluster weak;
  {
    const ValueBounds bounds(others_mdp);
    State fresh = others_mdp.start();
    for (Steps t = 0; t <= problem.deadline(); ++t) {
      fresh.time = static_cast<std::uint16_t>(t);
      const int choice = bounds.lower_choice(fresh);
      weak.lower.push_back(bounds.lower(fresh));
      weak.upper.push_back(bounds.upper(fresh));
      weak.commit.push_back(choice < 0 ? -1 : bounded[static_cast<std::size_t>(choice)]);
    }
  }
  LayeredSolution solution = dispatch(strong_mdp, options, true, &weak);
  // Back to the whole problem's skeletons: the bounded ones stay at their start.
  const auto whole_choice = [&](int choice, int t) {
    if (choice == kWeakChoice) return weak.commit[static_cast<std::size_t>(t)];
    return choice < 0 ? choice : kept[static_cast<std::size_t>(choice)];
  };
  solution.first_choice = whole_choice(solution.first_choice, 0);
  for (PolicyEntry& entry : solution.policy) {
    State whole = mdp.start();
    whole.time = entry.state.time;
    for (std::size_t i = 0; i < kept.size(); ++i) {
      const auto k = static_cast<std::size_t>(kept[i]);
      whole.refined[k] = entry.state.refined[i];
      whole.spent[k] = entry.state.spent[i];
      whole.execution[k] = entry.state.execution[i];
    }
    entry.choice = whole_choice(entry.choice, entry.state.time);
    entry.state = std::move(whole);
  }
  solution.split_kept = kept;
  solution.split_weak_upper = weak.upper.front();
  if (weak.upper.front() == 0.0 && solution.frontier_layer < 0 && solution.dropped == 0) {
    solution.exact = true;  // the bounded subtrees cannot succeed at all
    solution.upper = solution.lower;
  }
  solution.split_lower = solution.lower;
  solution.split_upper = solution.upper;
  solution.split_states = solution.states;
  solution.split_frontier_layer = std::exchange(solution.frontier_layer, -1);
  solution.split_stopped_by = std::exchange(solution.stopped_by, std::string());
  solution.split_layers = std::move(solution.layers);
  solution.layers.clear();
  return solution;
}

}  // namespace

LayeredSolution solve_layered(const Mdp& mdp, const LayeredSolveOptions& options) {
  detail::require_exact_size(mdp, "solve");
  if (!(options.tolerance >= 0.0 && options.tolerance <= 1.0)) {
    throw UsageError("solve: the tolerance must lie in [0, 1] (got " + std::to_string(options.tolerance) + ")");
  }
  if (options.split == SplitMode::always) {
    const std::vector<int> kept = split_plan(mdp);
    if (kept.empty()) {
      throw UsageError("solve: a split needs skeletons with at least two different first actions; all of " +
                       mdp.problem().name() + "'s begin with the same one");
    }
    return solve_split(mdp, options, kept);
  }
  LayeredSolution whole = dispatch(mdp, options, false, nullptr);
  if (whole.frontier_layer < 0 || options.split == SplitMode::never) return whole;
  const std::vector<int> kept = split_plan(mdp);
  if (kept.empty()) return whole;
  // Both intervals hold the optimum: keep the tighter end of each, and the policy of the
  // higher lower end.
  LayeredSolution split = solve_split(mdp, options, kept);
  if (split.lower > whole.lower) {
    whole.lower = split.lower;
    whole.first_choice = split.first_choice;
    whole.policy = std::move(split.policy);
  }
  whole.upper = std::min(whole.upper, split.upper);
  whole.dropped += split.dropped;
  whole.split_kept = std::move(split.split_kept);
  whole.split_weak_upper = split.split_weak_upper;
  whole.split_lower = split.split_lower;
  whole.split_upper = split.split_upper;
  whole.split_states = split.split_states;
  whole.split_frontier_layer = split.split_frontier_layer;
  whole.split_stopped_by = std::move(split.split_stopped_by);
  whole.split_layers = std::move(split.split_layers);
  whole.states += split.split_states;
  whole.peak_memory_bytes = std::max(whole.peak_memory_bytes, split.peak_memory_bytes);
  whole.peak_disk_bytes = std::max(whole.peak_disk_bytes, split.peak_disk_bytes);
  return whole;
}

}  // namespace ontime
