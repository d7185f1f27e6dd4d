#pragma once
// Internal (layered solver): how a state of the layered search is written down. A key packs,
// per skeleton, its refined count, PT and ET in bit fields just wide enough for the instance
// (a skeleton that can no longer succeed blanked), so that a state costs as few 64-bit words as
// possible and a successor's key is its state's key with a few fields rewritten (a mask and an
// or). Also the 32-bit codes that the scratch files hold per outcome, and the hash that places
// a key on its rank and in its shard. Every operation here is O(skeletons) or less.

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "ontime/mdp/mdp.hpp"
#include "solve/expectimax.hpp"

namespace ontime::layered {

using detail::CompactState;
using detail::PackedState;
using detail::PackedStateHash;

// ---- the per-outcome codes of the scratch files ----
//
// One 32-bit code per outcome: where the successor sits in the next layer (a shard's place, or
// an entry of the layer's list of successors owned by other ranks), or success, failure; a
// successor from which a tolerance dropped groups is preceded by kExtrasCode, and its factor
// and boost are the next two doubles of the layer's extras file. With rewards (SPEC §8), each
// success's reward is the next double of the extras file.
inline constexpr std::uint32_t kForeignBase = 0x8000'0000U;
inline constexpr std::uint32_t kSpecialBase = 0xFFFF'FFF0U;
inline constexpr std::uint32_t kSuccessCode = 0xFFFF'FFFFU;
inline constexpr std::uint32_t kFailureCode = 0xFFFF'FFFEU;
inline constexpr std::uint32_t kExtrasCode = 0xFFFF'FFFDU;

// The choice a split's step on the bounded subtrees stands for in the policy (mapped to the
// bounded skeleton with the best commit value when reported).
inline constexpr int kWeakChoice = -2;

// Where each skeleton's fields sit in a key: refined in just enough bits for the skeleton's
// length, PT and ET in just enough for 0 .. D + 1 and one more code for a blanked slot; with
// backtracking (SPEC §7), then one field of the same width per culprit slot for its restore
// value (an execution, 0 .. D + 1); with chains or expiry (SPEC §9), one such field per timed
// slot (the static execution before the timed action) and, with chains, one field just wide
// enough for their joint state; in a split, one more bit flags the copies one layer on (a step
// went to the bounded subtrees). A field never straddles two words, so that rewriting a
// skeleton's is a mask and an or.
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
    restore_slots_ = detail::recorded_slots(mdp.problem());
    for (int c = 0; c < restore_slots_; ++c) {
      const auto [word, shift] = place(counter_bits_);
      restore_[static_cast<std::size_t>(c)] = {word, shift};
    }
    if (mdp.has_chains()) {
      chain_bits_ = std::max(1, static_cast<int>(std::bit_width(static_cast<unsigned>(mdp.joint_chain_states() - 1))));
      const auto [word, shift] = place(chain_bits_);
      chains_ = {word, shift};
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

  // A state's key (its time is the layer's). A CompactBacktrackState's restore values are
  // written too, and a CompactTimedState's chains; a CompactState's only for a problem without
  // backtracking, chains or expiry.
  template <std::size_t W, class Compact>
  PackedState<W> encode(const Compact& state) const noexcept {
    PackedState<W> key;
    for (int k = 0; k < skeletons_; ++k) {
      const auto slot = static_cast<std::size_t>(k);
      key.words[static_cast<std::size_t>(word(k))] |=
          value(k, state.refined[slot], state.spent[slot], state.execution[slot]);
    }
    if constexpr (kHoldsRestore<Compact>) {
      for (int c = 0; c < restore_slots_; ++c) {
        const Place& place = restore_[static_cast<std::size_t>(c)];
        key.words[static_cast<std::size_t>(place.word)] |= code(state.restore[static_cast<std::size_t>(c)])
                                                           << place.shift;
      }
    }
    if constexpr (kHoldsChains<Compact>) {
      if (chain_bits_ > 0)
        key.words[static_cast<std::size_t>(chains_.word)] |= std::uint64_t{state.chains} << chains_.shift;
    }
    return key;
  }

  template <std::size_t W, class Compact>
  void decode(const PackedState<W>& key, int layer, Compact& out) const noexcept {
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
    if constexpr (kHoldsRestore<Compact>) {
      for (int c = 0; c < restore_slots_; ++c) {
        const Place& place = restore_[static_cast<std::size_t>(c)];
        out.restore[static_cast<std::size_t>(c)] =
            counter(key.words[static_cast<std::size_t>(place.word)] >> place.shift & counter_mask);
      }
    }
    if constexpr (kHoldsChains<Compact>) {
      out.chains = chain_bits_ == 0
                       ? std::uint16_t{0}
                       : static_cast<std::uint16_t>(key.words[static_cast<std::size_t>(chains_.word)] >> chains_.shift &
                                                    ((std::uint64_t{1} << chain_bits_) - 1));
    }
  }

 private:
  struct Field {
    int word, shift, refined_bits;
    std::uint64_t mask, blank;
  };
  struct Place {
    int word = 0, shift = 0;
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
  int restore_slots_ = 0;
  std::array<Place, detail::kMaxExactCulpritSlots> restore_{};
  int chain_bits_ = 0;  // 0: no chains
  Place chains_;
};

// The rank that owns a key, and the shard of a rank's layer table a key falls into: two mixes
// of the key other than the tables' hash, so that keys still spread over each table.
template <std::size_t W>
std::uint64_t placement_hash(const PackedState<W>& key) noexcept {
  std::uint64_t h = 0x2545f4914f6cdd1dULL;
  for (const std::uint64_t word : key.words) h = (h ^ word) * 0x9e3779b97f4a7c15ULL;
  return h ^ (h >> 29);
}

}  // namespace ontime::layered
