// The forward pass of the layered solver: layer t + 1 from layer t, until no state is left
// running or a cap or the stop ends it. Each rank expands its own states of layer t, block by
// block on its threads (Successors<W>), and files every successor: into the shard of the next
// layer's tables it hashes to (PlaceTable, one thread per shard) or, over ranks, to the rank that
// owns it, which answers with the successor's place there. Per outcome, the place (or success,
// failure) is written as a 32-bit code to layer t's scratch file, chunk by chunk; the caps
// (states, memory, disk) and the stop are checked by every rank together after each chunk, so
// that a cap ends the pass cleanly at a layer every rank agrees on, never by running out of
// memory. What the backward pass needs of a layer stays in its LayerRecord.
//
// Cost: one table insertion per outcome (prefetched a few keys ahead: the tables are far larger
// than the caches), two all_to_all exchanges per chunk over ranks.

#include <absl/container/flat_hash_map.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "ontime/util/error.hpp"
#include "ontime/util/parallel.hpp"
#include "solve/layered/search.hpp"

namespace ontime::layered {

template <std::size_t W>
std::vector<PackedState<W>> LayeredSearch<W>::forward(std::vector<Key> current) {
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
template <std::size_t W>
struct LayeredSearch<W>::Pending {
  Key key;
  std::uint32_t block;  // within the chunk
  std::uint32_t at;     // index of its code within the block's codes
};
// Each on cache lines of its own: threads filling neighbouring ones must not share lines.
template <std::size_t W>
struct alignas(64) LayeredSearch<W>::BlockOutput {
  std::vector<std::uint32_t> codes;
  std::vector<double> extras;
};
template <std::size_t W>
struct alignas(64) LayeredSearch<W>::PendingList {
  std::vector<Pending> list;
};
template <std::size_t W>
struct alignas(64) LayeredSearch<W>::ThreadBuffers {
  std::vector<PendingList> own;      // per shard
  std::vector<PendingList> foreign;  // per rank
};

template <std::size_t W>
Cut LayeredSearch<W>::expand(const std::vector<Key>& current, int t, std::vector<Key>& next) {
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
  const bool rewards = mdp_->problem().has_rewards() || mdp_->is_timed();  // a success's reward may not be 1
  std::vector<ThreadBuffers> buffers(threads_);
  for (ThreadBuffers& buffer : buffers) {
    buffer.own.resize(shards_);
    buffer.foreign.resize(static_cast<std::size_t>(ranks_));
  }
  std::vector<BlockOutput> blocks(kChunkBlocks);
  // With chains or expiry, each thread's table of plan values (made afresh for every chunk).
  std::vector<std::uint64_t> plan_bytes(threads_, 0);
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
            // With rewards (SPEC §8), a success's reward follows in the extras.
            if (outcome.status == Status::success && rewards) output.extras.push_back(outcome.reward);
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
        plan_bytes[thread] = std::max(plan_bytes[thread], successors.plan_bytes());
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
            blocks[pending[i].block].codes[pending[i].at] = place(pending[i].key, PlaceTable<W>::hash(pending[i].key));
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
    for (const std::uint64_t bytes : plan_bytes) chunk_bytes += bytes;
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

// The members defined here, for every key width search_layers dispatches to (search.hpp).
#define ONTIME_INSTANTIATE_FORWARD_PASS(W)                                                           \
  template std::vector<PackedState<(W)>> LayeredSearch<(W)>::forward(std::vector<PackedState<(W)>>); \
  template Cut LayeredSearch<(W)>::expand(const std::vector<PackedState<(W)>>&, int, std::vector<PackedState<(W)>>&);
ONTIME_LAYERED_KEY_WIDTHS(ONTIME_INSTANTIATE_FORWARD_PASS)
#undef ONTIME_INSTANTIATE_FORWARD_PASS

}  // namespace ontime::layered
