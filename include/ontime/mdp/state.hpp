#pragma once
// The MDP state of SPEC §2: the steps used and, per skeleton, the actions refined, the steps
// spent on the current action and the execution time of the refined ones; with backtracking
// (SPEC §7), the execution before each action that may be blamed; with exogenous chains and
// actions that expire (SPEC §9), the chains' joint state and the static execution before each
// timed action.
//
// Up to kInlineSkeletons skeletons the per-skeleton values live inside the object, so that
// the hot paths (transitions, searches, exact solving) copy a state without allocating;
// beyond, they live in one heap array per field, sized once by Mdp::start(). Unused inline
// slots stay zero, so that equal states compare equal whatever their history. The exact
// solver and exact evaluation key their tables by a compact copy and accept at most
// kMaxExactSkeletons skeletons.

#include <algorithm>
#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace ontime {

// Skeletons whose per-skeleton values a State holds without a heap allocation.
inline constexpr int kInlineSkeletons = 16;
// The most skeletons the exact solver (`optimal`) and exact evaluation take: their memo tables
// are keyed by a fixed-size copy of the state.
inline constexpr int kMaxExactSkeletons = kInlineSkeletons;

// One value per skeleton: inline for up to kInlineSkeletons, else in a heap array. Written by
// hand rather than with a small-vector library because State is part of the public interface,
// which stays free of third-party headers, and because a copy must reuse an existing heap
// array of the same size (a search copies one root state into its scratch state per
// iteration without allocating).
template <class T>
class PerSkeleton {
 public:
  // Room for kInlineSkeletons skeletons, inline, every value zero.
  PerSkeleton() noexcept : data_(inline_.data()) {}
  // Zero values for `count` skeletons.
  explicit PerSkeleton(std::size_t count) : PerSkeleton() {
    if (count > static_cast<std::size_t>(kInlineSkeletons)) {
      heap_ = std::make_unique<T[]>(count);
      heap_count_ = count;
      data_ = heap_.get();
    }
  }
  // Copies and moves keep data_ on their own storage. The inline case (every problem of up to
  // kInlineSkeletons skeletons, and every exact search) is a plain copy of the arrays.
  PerSkeleton(const PerSkeleton& other) : inline_(other.inline_), data_(inline_.data()) {
    if (other.heap_) [[unlikely]]
      assign_heap(other);
  }
  PerSkeleton& operator=(const PerSkeleton& other) {
    if (!other.heap_ && !heap_) [[likely]] {
      inline_ = other.inline_;
    } else if (this != &other) {
      inline_ = other.inline_;
      assign_heap(other);
    }
    return *this;
  }
  PerSkeleton(PerSkeleton&& other) noexcept
      : inline_(other.inline_), heap_count_(other.heap_count_), heap_(std::move(other.heap_)) {
    data_ = heap_ ? heap_.get() : inline_.data();
    other.heap_count_ = 0;
    other.data_ = other.inline_.data();
  }
  PerSkeleton& operator=(PerSkeleton&& other) noexcept {
    if (this != &other) {
      inline_ = other.inline_;
      heap_count_ = other.heap_count_;
      heap_ = std::move(other.heap_);
      data_ = heap_ ? heap_.get() : inline_.data();
      other.heap_count_ = 0;
      other.data_ = other.inline_.data();
    }
    return *this;
  }
  ~PerSkeleton() = default;

  // Skeleton k's value; k must be below capacity().
  T& operator[](std::size_t k) noexcept {
    assert(k < capacity());
    return data_[k];
  }
  // Skeleton k's value; k must be below capacity().
  const T& operator[](std::size_t k) const noexcept {
    assert(k < capacity());
    return data_[k];
  }
  // The first value; capacity() values follow.
  T* data() noexcept { return data_; }
  // The first value; capacity() values follow.
  const T* data() const noexcept { return data_; }
  // Skeletons this object has room for.
  std::size_t capacity() const noexcept { return heap_ ? heap_count_ : inline_.size(); }

  friend bool operator==(const PerSkeleton& a, const PerSkeleton& b) noexcept {
    return a.capacity() == b.capacity() && std::equal(a.data_, a.data_ + a.capacity(), b.data_);
  }

 private:
  // Takes other's heap array (reusing this one's when the sizes match), or drops this one's.
  void assign_heap(const PerSkeleton& other) {
    if (!other.heap_) {
      heap_.reset();
      heap_count_ = 0;
      data_ = inline_.data();
      return;
    }
    if (heap_count_ != other.heap_count_) {
      heap_ = std::make_unique_for_overwrite<T[]>(other.heap_count_);
      heap_count_ = other.heap_count_;
    }
    std::copy_n(other.heap_.get(), heap_count_, heap_.get());
    data_ = heap_.get();
  }

  std::array<T, kInlineSkeletons> inline_{};
  T* data_;  // inline_.data() or heap_.get()
  std::size_t heap_count_ = 0;
  std::unique_ptr<T[]> heap_;
};

struct State {
  State() noexcept = default;
  // The start state of a problem with `skeleton_count` skeletons and `recorded_slots` actions
  // whose execution before them is recorded (Mdp::start() makes it).
  explicit State(std::size_t skeleton_count, std::size_t recorded_slots = 0)
      : refined(skeleton_count), spent(skeleton_count), execution(skeleton_count), restore(recorded_slots) {}

  std::uint16_t time = 0;  // CT: steps used
  // Exogenous chains (SPEC §9): the chains' joint state (Mdp::joint_chain_state), 0 without chains.
  std::uint16_t chains = 0;
  PerSkeleton<std::uint8_t> refined;  // l_k: actions refined
  PerSkeleton<std::uint16_t> spent;   // PT_k: steps on action l_k
  // ET_k: execution steps of the refined actions, saturated at deadline + 1 (any larger
  // value is equally too slow, and saturation keeps equivalent states equal).
  PerSkeleton<std::uint16_t> execution;
  // B_c, the execution steps before action c on its path, recorded when c was refined, 0 while it
  // is not, for every action c whose B_c matters: with backtracking (SPEC §7) the actions some
  // action may blame (by Problem::culprit_slot; B_c is restored by a backtrack to c), with chains
  // or expiry (SPEC §9) the timed actions (by Problem::timed_slot; c starts B_c after its plan is
  // complete, plus the chain-dependent executions before it; their slots follow the culprits'). A
  // problem with both has both kinds (an action may have a slot of each); a backtrack to c zeroes
  // the slots of c and of the actions below it. All zero, and unused, without either.
  PerSkeleton<std::uint16_t> restore;

  friend bool operator==(const State&, const State&) = default;
};

enum class Status : std::uint8_t { running, success, failure };

}  // namespace ontime
