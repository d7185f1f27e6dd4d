#pragma once
// Internal (layered solver): where the layers live. Forward, the next layer is built in shard
// tables (PlaceTable: key -> its place in the layer, in the order keys arrived), which ask a
// rank's MemoryBudget before they grow, so that a memory cap ends the pass cleanly instead of an
// allocation failing. Each finished layer goes to disk, in ScratchFiles of the rank's scratch
// directory: its keys, one 32-bit code per outcome and the doubles of the outcomes a tolerance
// touched; the backward pass reads them back, last layer first. Errors name the layer and file.
//
// Cost: a table holds each key once with a 4-byte index, at most half full (linear probing);
// growing doubles it, and briefly holds the old and the new slots together.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <utility>
#include <vector>

#include "solve/layered/keys.hpp"

namespace ontime::layered {

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

// A scratch file written or read in pieces; errors name the layer and the file (and throw
// ResourceLimitError).
class ScratchFile {
 public:
  ScratchFile(std::filesystem::path path, int layer, const char* mode);
  ~ScratchFile();
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
  void close();

 private:
  [[noreturn]] void fail(const char* what) const;
  std::filesystem::path path_;
  int layer_;
  std::FILE* file_ = nullptr;
};

}  // namespace ontime::layered
