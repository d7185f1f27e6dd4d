#pragma once
// Internal (layered solver): LayeredSearch<W>, one solve of the layered search on keys of W
// words, and what its parts share. The header of include/ontime/solve/layered_solver.hpp says
// what it computes and guarantees; its members are defined by role, one file each:
//   search.cpp          the results every rank returns (finish), the dispatch by key width
//   forward_pass.cpp    builds the layers, writing each one's codes (forward, expand)
//   storage.cpp         the layers' scratch files (keys written, read back, removed)
//   backward_pass.cpp   values the layers from the last to the first (backward, value_layer)
//   frontier.cpp        where the forward pass stopped and why, and the bounds of its last layer
//   rank_exchange.cpp   what ranks exchange: sums, maxima, cuts, values of foreign successors
// Each of those files instantiates the members it defines for every key width that
// search_layers dispatches to (ONTIME_LAYERED_KEY_WIDTHS).

#include <atomic>
#include <bit>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "ontime/solve/layered_solver.hpp"
#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/parallel.hpp"
#include "solve/layered/keys.hpp"
#include "solve/layered/storage.hpp"
#include "solve/layered/successors.hpp"
#include "solve/scratch_directory.hpp"

namespace ontime::layered {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Why the forward pass ended early; the lowest nonzero reason over the ranks wins.
enum class Cut : std::uint8_t { none = 0, stop, states, memory, disk };

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

// Runs LayeredSearch on keys of the fewest words the instance needs (with a split's flag when
// `flag`); `weak` is the split's bounded part, null for the whole tree. The bounds a tolerance
// needs are built here (ResourceLimitError when their tables are too large).
LayeredSolution search_layers(const Mdp& mdp, const LayeredSolveOptions& options, bool flag, const WeakCluster* weak);

// The key widths search_layers dispatches to: X(words) for each.
#define ONTIME_LAYERED_KEY_WIDTHS(X) X(1) X(2) X(4) X(kMaxExactSkeletons) X(kMaxExactSkeletons + 1)
static_assert(kMaxExactSkeletons > 4, "the key widths must be distinct");

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

  struct PolicyRecord {
    int layer = 0;
    Key key;
    int choice = -1;
    Bounds value;
  };

  // The forward pass's buffers of one chunk (forward_pass.cpp).
  struct Pending;
  struct BlockOutput;
  struct PendingList;
  struct ThreadBuffers;
  // The value of one state after another in the backward pass (backward_pass.cpp).
  struct StateValue;

  int owner_of(const Key& key) const noexcept {
    return ranks_ == 1 ? 0 : static_cast<int>((placement_hash(key) >> 40) % static_cast<std::uint64_t>(ranks_));
  }
  std::size_t shard_of(const Key& key) const noexcept {
    return static_cast<std::size_t>(placement_hash(key) & (shards_ - 1));
  }

  // ---- forward: enumerate the layers (forward_pass.cpp) ----

  std::vector<Key> forward(std::vector<Key> current);
  // Builds layer t + 1 from this rank's states of layer t, writing layer t's codes; returns a
  // cut if a cap ended it (every rank agrees).
  Cut expand(const std::vector<Key>& current, int t, std::vector<Key>& next);

  // ---- the layers on disk (storage.cpp) ----

  void write_keys(int t, const std::vector<Key>& keys);
  std::vector<Key> read_keys(int t, std::size_t count);
  void remove_layer_files(int t);

  // ---- backward: value the layers from the last to the first (backward_pass.cpp) ----

  void backward(std::vector<Key> top_keys);
  void value_layer(const std::vector<Key>& keys, int t, const std::vector<Bounds>& next_values,
                   std::vector<Bounds>& values, std::vector<int>& choices);
  void keep_policy(const std::vector<Key>& keys, const std::vector<Bounds>& values, const std::vector<int>& choices,
                   int t);

  // ---- the frontier (frontier.cpp) ----

  // The bounds (and the lower-bound policy's choices) of the states of the layer a cut left last.
  void value_frontier(const std::vector<Key>& keys, int t, std::vector<Bounds>& values, std::vector<int>& choices);
  // Why the forward pass stopped at layer t, in words.
  std::string describe(Cut cut, int t) const;

  // ---- results, shared by every rank (search.cpp) ----

  void finish();

  // ---- exchanges between ranks, no-ops for one process (rank_exchange.cpp) ----

  std::vector<std::string> gather(const std::string& bytes) const;
  std::uint64_t sum_over_ranks(std::uint64_t count) const;
  std::uint64_t max_over_ranks(std::uint64_t count) const;
  // The first rank's reason to cut, if any rank has one (every rank must call it).
  Cut first_cut(Cut mine) const;
  // Over ranks: the values of the successors this rank's states of layer t have on other ranks.
  std::vector<Bounds> fetch_foreign_values(const LayerRecord& record, const std::vector<Bounds>& next_values);

  void note_memory(std::uint64_t bytes) {
    std::uint64_t seen = peak_memory_.load(std::memory_order_relaxed);
    while (bytes > seen && !peak_memory_.compare_exchange_weak(seen, bytes)) {
    }
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

}  // namespace ontime::layered
