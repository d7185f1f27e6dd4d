#include "ontime/layered_solver.hpp"

#include <absl/container/flat_hash_map.h>
#include <absl/container/flat_hash_set.h>
#include <stdlib.h>  // mkdtemp
#include <unistd.h>  // getpid

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "expectimax.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/byte_packing.hpp"
#include "ontime/error.hpp"
#include "ontime/parallel.hpp"
#include "ontime/value_bounds.hpp"

namespace ontime {
namespace {

using detail::CompactState;
using detail::PackedState;
using detail::PackedStateHash;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Where each skeleton's fields sit in a key: refined in just enough bits for the skeleton's
// length, PT and ET in just enough for 0 .. D + 1 and one more code for a blanked slot. A
// skeleton's fields never straddle two words, so that encoding is a shift and an or per skeleton.
class KeyLayout {
 public:
  explicit KeyLayout(const Mdp& mdp)
      : skeletons_(mdp.skeleton_count()),
        blank_code_(static_cast<std::uint64_t>(mdp.deadline()) + 2),
        counter_bits_(static_cast<int>(std::bit_width(blank_code_))) {
    int used = 0;
    for (int k = 0; k < skeletons_; ++k) {
      const int refined_bits = std::bit_width(static_cast<unsigned>(mdp.problem().skeleton_length(k)));
      const int bits = refined_bits + 2 * counter_bits_;
      if (used + bits > 64) {
        ++words_;
        used = 0;
      }
      fields_[static_cast<std::size_t>(k)] = {words_ - 1, used, refined_bits};
      used += bits;
    }
  }

  int words() const noexcept { return words_; }

  template <std::size_t W>
  PackedState<W> encode(const CompactState& state) const noexcept {
    PackedState<W> key;
    for (int k = 0; k < skeletons_; ++k) {
      const auto slot = static_cast<std::size_t>(k);
      const Field& field = fields_[slot];
      const std::uint64_t value = std::uint64_t{state.refined[slot]} | code(state.spent[slot]) << field.refined_bits |
                                  code(state.execution[slot]) << (field.refined_bits + counter_bits_);
      key.words[static_cast<std::size_t>(field.word)] |= value << field.shift;
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
      const std::uint64_t value = key.words[static_cast<std::size_t>(field.word)] >> field.shift;
      out.refined[slot] = static_cast<std::uint8_t>(value & ((std::uint64_t{1} << field.refined_bits) - 1));
      out.spent[slot] = counter(value >> field.refined_bits & counter_mask);
      out.execution[slot] = counter(value >> (field.refined_bits + counter_bits_) & counter_mask);
    }
  }

 private:
  struct Field {
    int word, shift, refined_bits;
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
  std::array<Field, kMaxExactSkeletons> fields_{};
};

// The rank that owns a key: a mix of the key other than the tables' hash, so that one rank's
// keys still spread over its table.
template <std::size_t W>
int owner_of(const PackedState<W>& key, int ranks) noexcept {
  if (ranks == 1) return 0;
  std::uint64_t h = 0x2545f4914f6cdd1dULL;
  for (const std::uint64_t word : key.words) h = (h ^ word) * 0x9e3779b97f4a7c15ULL;
  return static_cast<int>((h >> 32) % static_cast<std::uint64_t>(ranks));
}

// Bytes a flat hash table of `entries` slots of `slot_bytes` holds: a power-of-two capacity at
// most 7/8 full, one control byte per slot.
std::uint64_t table_bytes(std::uint64_t entries, std::size_t slot_bytes) {
  const std::uint64_t capacity = std::bit_ceil(std::max<std::uint64_t>(entries + entries / 7 + 1, 16));
  return capacity * (slot_bytes + 1);
}

// Why the forward pass ended early; the lowest nonzero reason over the ranks wins.
enum class Cut : std::uint8_t { none = 0, stop, states, memory, disk };

// Thrown inside a layer's expansion to end it at the memory cap or the stop condition.
struct ExpansionCut {
  Cut cut;
};

// A private directory for one rank's layer files, removed with everything in it.
class ScratchDirectory {
 public:
  ScratchDirectory(const std::filesystem::path& parent_or_empty, int rank) {
    std::error_code error;
    const std::filesystem::path parent =
        parent_or_empty.empty() ? std::filesystem::temp_directory_path(error) : parent_or_empty;
    std::string pattern =
        (parent / ("ontime-layers-" + std::to_string(::getpid()) + "-rank" + std::to_string(rank) + "-XXXXXX"))
            .string();
    if (error || ::mkdtemp(pattern.data()) == nullptr) {
      throw UsageError("cannot make a scratch directory for the layers in " + parent.string() +
                       " (choose another with --scratch)");
    }
    path_ = pattern;
  }
  ~ScratchDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;

  std::filesystem::path layer(int t) const { return path_ / ("layer-" + std::to_string(t) + ".keys"); }

 private:
  std::filesystem::path path_;
};

struct Bounds {
  double lower = 0;
  double upper = 0;
};

template <std::size_t W>
class LayeredSearch {
 public:
  using Key = PackedState<W>;
  using KeySet = absl::flat_hash_set<Key, PackedStateHash>;
  using ValueMap = absl::flat_hash_map<Key, Bounds, PackedStateHash>;

  LayeredSearch(const Mdp& mdp, const LayeredSolveOptions& options, const KeyLayout& layout)
      : mdp_(&mdp),
        options_(&options),
        layout_(&layout),
        rank_(options.ranks != nullptr ? options.ranks->rank() : 0),
        ranks_(options.ranks != nullptr ? options.ranks->size() : 1),
        scratch_(options.scratch_directory, rank_) {}

  LayeredSolution run() {
    solution_.key_bytes = sizeof(Key);
    std::vector<Key> current = forward();
    backward(std::move(current));
    finish();
    return std::move(solution_);
  }

 private:
  // ---- forward: enumerate the layers, writing each one left behind to disk ----

  std::vector<Key> forward() {
    CompactState start = detail::compact(mdp_->start(), mdp_->skeleton_count());
    detail::blank_hopeless(*mdp_, start);
    const Key start_key = layout_->encode<W>(start);
    std::vector<Key> current;
    if (owner_of(start_key, ranks_) == rank_) current.push_back(start_key);
    for (int t = 0;; ++t) {
      const std::uint64_t states = sum_over_ranks(current.size());
      solution_.layers.push_back({.layer = t, .states = states});
      solution_.states += states;
      top_ = t;
      const auto started = Clock::now();
      Cut cut = Cut::none;
      if (options_->stop && options_->stop()) cut = Cut::stop;
      if (options_->max_disk_bytes != 0 && disk_bytes_ + current.size() * sizeof(Key) > options_->max_disk_bytes) {
        cut = Cut::disk;
      }
      std::optional<KeySet> next;
      cut = first_cut(cut);
      if (cut == Cut::none) {
        try {
          next = expand(current, t);
        } catch (const ExpansionCut& reached) {
          cut = reached.cut;  // agreed by every rank
        }
      }
      if (cut == Cut::none) {
        const std::uint64_t next_states = sum_over_ranks(next->size());
        if (options_->max_states != 0 && solution_.states + next_states > options_->max_states) cut = Cut::states;
        const std::uint64_t lookup_entries = ranks_ == 1 ? next->size() : next_states;
        const std::uint64_t backward_bytes = table_bytes(lookup_entries, sizeof(typename ValueMap::value_type)) +
                                             current.size() * (sizeof(Key) + sizeof(Bounds) + sizeof(int)) +
                                             table_bytes(current.size(), sizeof(typename ValueMap::value_type));
        note_memory(backward_bytes);
        if (options_->max_memory_bytes != 0 && backward_bytes > options_->max_memory_bytes) cut = Cut::memory;
        cut = first_cut(cut);
        if (cut == Cut::none && next_states == 0) {
          solution_.layers.back().forward_seconds = seconds_since(started);
          report(solution_.layers.back());
          return current;  // the last layer: every successor ends the episode
        }
      }
      if (cut != Cut::none) {
        frontier_ = t;
        solution_.stopped_by = describe(cut, t);
        report(solution_.layers.back());
        return current;
      }
      write_layer(t, current);
      current.assign(next->begin(), next->end());
      next.reset();
      solution_.layers.back().forward_seconds = seconds_since(started);
      report(solution_.layers.back());
    }
  }

  // The next layer's states owned by this rank, from this rank's states of layer t.
  KeySet expand(const std::vector<Key>& current, int t) {
    const unsigned workers = worker_count(current.size(), options_->threads);
    // found[thread][rank]: the successors a thread found, by owner.
    std::vector<std::vector<KeySet>> found(workers, std::vector<KeySet>(static_cast<std::size_t>(ranks_)));
    std::vector<std::atomic<std::uint64_t>> held(workers);
    std::vector<std::vector<Outcome>> scratch_outcomes(workers);
    const std::uint64_t base = current.capacity() * sizeof(Key);
    note_memory(base);
    Cut cut = Cut::none;
    try {
      for_each_block(current.size(), options_->threads, kBlock, [&](unsigned thread) {
        return [&, thread](std::uint64_t begin, std::uint64_t end) {
          std::vector<KeySet>& mine = found[thread];
          std::vector<Outcome>& outcomes = scratch_outcomes[thread];
          CompactState state;
          for (std::uint64_t i = begin; i < end; ++i) {
            layout_->decode(current[i], t, state);
            outcomes_of(state, outcomes);
            // Every successor's slot is prefetched first, so that the table's cache misses overlap.
            for (const Outcome& outcome : outcomes) {
              if (outcome.status == Status::running)
                mine[static_cast<std::size_t>(outcome.owner)].prefetch(outcome.key);
            }
            // Outcomes that differ only in an execution time too slow to matter share their key.
            const Key* previous = nullptr;
            for (const Outcome& outcome : outcomes) {
              if (outcome.status != Status::running || (previous != nullptr && *previous == outcome.key)) continue;
              mine[static_cast<std::size_t>(outcome.owner)].insert(outcome.key);
              previous = &outcome.key;
            }
          }
          std::uint64_t bytes = 0;
          for (const KeySet& set : mine) bytes += set.capacity() * (sizeof(Key) + 1);
          held[thread] = bytes;
          std::uint64_t total = base;
          for (const auto& each : held) total += each.load();
          note_memory(total);
          if (options_->max_memory_bytes != 0 && total > options_->max_memory_bytes) throw ExpansionCut{Cut::memory};
          if (thread == 0 && options_->stop && options_->stop()) throw ExpansionCut{Cut::stop};
        };
      });
    } catch (const ExpansionCut& reached) {
      cut = reached.cut;
    }
    // Every rank learns of any rank's cut before the exchange, which all must then join.
    cut = first_cut(cut);
    if (cut != Cut::none) throw ExpansionCut{cut};
    // Merge the threads' sets per owner into thread 0's.
    std::vector<KeySet>& merged = found[0];
    for (unsigned thread = 1; thread < workers; ++thread) {
      for (std::size_t r = 0; r < merged.size(); ++r) {
        merged[r].insert(found[thread][r].begin(), found[thread][r].end());
        KeySet().swap(found[thread][r]);
      }
    }
    KeySet own = std::move(merged[static_cast<std::size_t>(rank_)]);
    if (ranks_ > 1) {
      std::vector<std::string> parts(static_cast<std::size_t>(ranks_));
      for (std::size_t r = 0; r < parts.size(); ++r) {
        if (static_cast<int>(r) == rank_) continue;
        parts[r] = pack_keys(merged[r]);
        KeySet().swap(merged[r]);
      }
      for (const std::string& part : options_->ranks->all_to_all(parts)) unpack_keys(part, own);
      const std::uint64_t bytes = base + own.capacity() * (sizeof(Key) + 1);
      note_memory(bytes);
      cut = first_cut(options_->max_memory_bytes != 0 && bytes > options_->max_memory_bytes ? Cut::memory : Cut::none);
      if (cut != Cut::none) throw ExpansionCut{cut};
    }
    return own;
  }

  void write_layer(int t, const std::vector<Key>& keys) {
    const std::filesystem::path path = scratch_.layer(t);
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(keys.data()), static_cast<std::streamsize>(keys.size() * sizeof(Key)));
    out.close();
    if (!out) {
      throw ResourceLimitError("layer " + std::to_string(t) + ": cannot write " + std::to_string(keys.size()) +
                               " states to " + path.string() + " (disk full?); free space or set --scratch");
    }
    disk_bytes_ += keys.size() * sizeof(Key);
    solution_.peak_disk_bytes = std::max(solution_.peak_disk_bytes, disk_bytes_);
  }

  std::vector<Key> read_layer(int t) {
    const std::filesystem::path path = scratch_.layer(t);
    std::error_code error;
    const auto bytes = std::filesystem::file_size(path, error);
    if (error || bytes % sizeof(Key) != 0) {
      throw ResourceLimitError("layer " + std::to_string(t) + ": cannot read back " + path.string());
    }
    std::vector<Key> keys(bytes / sizeof(Key));
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(keys.data()), static_cast<std::streamsize>(bytes));
    if (!in) throw ResourceLimitError("layer " + std::to_string(t) + ": cannot read back " + path.string());
    in.close();
    std::filesystem::remove(path, error);
    disk_bytes_ -= bytes;
    return keys;
  }

  // ---- backward: value the layers from the last to the first ----

  void backward(std::vector<Key> top_keys) {
    std::optional<ValueBounds> bounds;
    if (frontier_ >= 0) {
      try {
        bounds.emplace(*mdp_);
      } catch (const ResourceLimitError&) {
        // Tables too large for this deadline: the frontier gets the trivial bounds [0, 1].
      }
    }
    ValueMap next_values;
    for (int t = top_; t >= 0; --t) {
      const auto started = Clock::now();
      std::vector<Key> keys = t == top_ ? std::move(top_keys) : read_layer(t);
      std::vector<Bounds> values(keys.size());
      std::vector<int> choices(keys.size(), -1);
      if (t == frontier_) {
        for_each_block(keys.size(), options_->threads, kBlock, [&](unsigned) {
          return [&](std::uint64_t begin, std::uint64_t end) {
            CompactState state;
            for (std::uint64_t i = begin; i < end; ++i) {
              layout_->decode(keys[i], t, state);
              if (bounds) {
                values[i] = {bounds->lower(state), bounds->upper(state)};
                choices[i] = bounds->lower_choice(state);
              } else {
                values[i] = {0.0, mdp_->any_can_succeed(state) ? 1.0 : 0.0};
              }
            }
          };
        });
      } else {
        if (ranks_ > 1) fetch_foreign_values(keys, t, next_values);
        for_each_block(keys.size(), options_->threads, kBlock, [&](unsigned) {
          return [&, outcomes = std::vector<Outcome>()](std::uint64_t begin, std::uint64_t end) mutable {
            CompactState state;
            for (std::uint64_t i = begin; i < end; ++i) {
              layout_->decode(keys[i], t, state);
              values[i] = value_of(state, next_values, outcomes, choices[i]);
            }
          };
        });
      }
      if (t < options_->policy_layers) keep_policy(keys, values, choices, t);
      if (t == 0 && !keys.empty()) {
        start_ = values[0];
        start_choice_ = choices[0];
        has_start_ = true;
      }
      ValueMap layer_values;
      layer_values.reserve(keys.size());
      for (std::size_t i = 0; i < keys.size(); ++i) layer_values.emplace(keys[i], values[i]);
      note_memory(table_bytes(next_values.size(), sizeof(typename ValueMap::value_type)) +
                  keys.size() * (sizeof(Key) + sizeof(Bounds) + sizeof(int)) +
                  layer_values.capacity() * (sizeof(typename ValueMap::value_type) + 1));
      next_values = std::move(layer_values);
      LayerFigures& figures = solution_.layers[static_cast<std::size_t>(t)];
      figures.backward_seconds = seconds_since(started);
      figures.backward = true;
      report(figures);
    }
  }

  // A state's outcomes: for each useful choice in increasing order, the outcomes in the Mdp's
  // order, with the key and owner of each running successor.
  struct Outcome {
    double probability;
    Key key;
    int choice;
    int owner;
    Status status;
  };
  void outcomes_of(const CompactState& state, std::vector<Outcome>& out) const {
    out.clear();
    for (const int choice : mdp_->useful_choices(state)) {
      mdp_->for_each_outcome(state, choice, [&](double probability, Status status, CompactState next) {
        Outcome outcome{probability, Key{}, choice, 0, status};
        if (status == Status::running) {
          detail::blank_hopeless(*mdp_, next);
          outcome.key = layout_->encode<W>(next);
          outcome.owner = owner_of(outcome.key, ranks_);
        }
        out.push_back(outcome);
      });
    }
  }

  // V (or its bounds) of a state below the frontier, from the next layer's values; the same
  // sums in the same order, and the same tie rule, as the memoised solver.
  Bounds value_of(const CompactState& state, const ValueMap& next_values, std::vector<Outcome>& outcomes,
                  int& choice) const {
    outcomes_of(state, outcomes);
    for (const Outcome& outcome : outcomes) {
      if (outcome.status == Status::running) next_values.prefetch(outcome.key);
    }
    double best_lower = -1.0;
    Bounds best{0.0, 0.0};
    double upper = 0.0;
    choice = -1;
    const Key* previous = nullptr;  // the last successor looked up, and its values
    Bounds value;
    for (std::size_t i = 0; i < outcomes.size();) {
      const int candidate = outcomes[i].choice;
      double lower_sum = 0.0;
      double upper_sum = 0.0;
      for (; i < outcomes.size() && outcomes[i].choice == candidate; ++i) {
        const Outcome& outcome = outcomes[i];
        if (outcome.status == Status::success) {
          lower_sum += outcome.probability;
          upper_sum += outcome.probability;
        } else if (outcome.status == Status::running) {
          if (previous == nullptr || !(*previous == outcome.key)) {
            const auto found = next_values.find(outcome.key);
            if (found == next_values.end()) throw std::logic_error("layered solver: a successor was not enumerated");
            value = found->second;
            previous = &outcome.key;
          }
          lower_sum += outcome.probability * value.lower;
          upper_sum += outcome.probability * value.upper;
        }
      }
      if (lower_sum > best_lower + OptimalSolver::kTieTolerance) {
        best_lower = lower_sum;
        best.lower = lower_sum;
        choice = candidate;
      }
      upper = std::max(upper, upper_sum);
    }
    best.upper = upper;
    return best;
  }

  // Over ranks: asks the owners of the successors of this rank's states for their values.
  void fetch_foreign_values(const std::vector<Key>& keys, int t, ValueMap& next_values) {
    const unsigned workers = worker_count(keys.size(), options_->threads);
    std::vector<std::vector<KeySet>> wanted(workers, std::vector<KeySet>(static_cast<std::size_t>(ranks_)));
    for_each_block(keys.size(), options_->threads, kBlock, [&](unsigned thread) {
      return [&, thread, outcomes = std::vector<Outcome>()](std::uint64_t begin, std::uint64_t end) mutable {
        CompactState state;
        for (std::uint64_t i = begin; i < end; ++i) {
          layout_->decode(keys[i], t, state);
          outcomes_of(state, outcomes);
          for (const Outcome& outcome : outcomes) {
            if (outcome.status == Status::running && outcome.owner != rank_) {
              wanted[thread][static_cast<std::size_t>(outcome.owner)].insert(outcome.key);
            }
          }
        }
      };
    });
    std::vector<std::string> requests(static_cast<std::size_t>(ranks_));
    for (std::size_t r = 0; r < requests.size(); ++r) {
      for (unsigned thread = 1; thread < workers; ++thread)
        wanted[0][r].insert(wanted[thread][r].begin(), wanted[thread][r].end());
      requests[r] = pack_keys(wanted[0][r]);
    }
    wanted.clear();
    // Answer the others' requests from this rank's values of the next layer.
    std::vector<std::string> answers;
    for (const std::string& request : options_->ranks->all_to_all(requests)) {
      std::string answer(request.size() / sizeof(Key) * sizeof(Bounds), '\0');
      for (std::size_t i = 0; i < request.size() / sizeof(Key); ++i) {
        Key key;
        std::memcpy(key.words.data(), request.data() + i * sizeof(Key), sizeof(Key));
        const auto found = next_values.find(key);
        if (found == next_values.end()) throw std::logic_error("layered solver: a rank asked for an unknown state");
        std::memcpy(answer.data() + i * sizeof(Bounds), &found->second, sizeof(Bounds));
      }
      answers.push_back(std::move(answer));
    }
    const std::vector<std::string> replies = options_->ranks->all_to_all(answers);
    for (std::size_t r = 0; r < replies.size(); ++r) {
      for (std::size_t i = 0; i < replies[r].size() / sizeof(Bounds); ++i) {
        Key key;
        Bounds value;
        std::memcpy(key.words.data(), requests[r].data() + i * sizeof(Key), sizeof(Key));
        std::memcpy(&value, replies[r].data() + i * sizeof(Bounds), sizeof(Bounds));
        next_values.emplace(key, value);
      }
    }
  }

  void keep_policy(const std::vector<Key>& keys, const std::vector<Bounds>& values, const std::vector<int>& choices,
                   int t) {
    for (std::size_t i = 0; i < keys.size(); ++i) {
      policy_.push_back({t, keys[i], choices[i], values[i]});
    }
  }

  // ---- results, shared by every rank ----

  void finish() {
    const bool exact = frontier_ < 0;
    solution_.peak_memory_bytes = peak_memory_.load();
    BytePacker packer;
    packer.put(static_cast<std::uint8_t>(has_start_));
    packer.put(start_.lower);
    packer.put(start_.upper);
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
        solution_.upper = exact ? lower : upper;
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
    solution_.exact = exact;
    solution_.frontier_layer = frontier_;
    std::sort(policy.begin(), policy.end(), [](const PolicyRecord& a, const PolicyRecord& b) {
      return a.layer != b.layer ? a.layer < b.layer : a.key.words < b.key.words;
    });
    for (const PolicyRecord& record : policy) {
      CompactState compact;
      layout_->decode(record.key, record.layer, compact);
      State state = mdp_->start();
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

  static std::string pack_keys(const KeySet& keys) {
    std::string bytes(keys.size() * sizeof(Key), '\0');
    std::size_t offset = 0;
    for (const Key& key : keys) {
      std::memcpy(bytes.data() + offset, key.words.data(), sizeof(Key));
      offset += sizeof(Key);
    }
    return bytes;
  }

  static void unpack_keys(const std::string& bytes, KeySet& into) {
    for (std::size_t offset = 0; offset + sizeof(Key) <= bytes.size(); offset += sizeof(Key)) {
      Key key;
      std::memcpy(key.words.data(), bytes.data() + offset, sizeof(Key));
      into.insert(key);
    }
  }

  void note_memory(std::uint64_t bytes) {
    std::uint64_t seen = peak_memory_.load(std::memory_order_relaxed);
    while (bytes > seen && !peak_memory_.compare_exchange_weak(seen, bytes)) {
    }
  }

  std::string describe(Cut cut, int t) const {
    const std::string at =
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
        return at + ": writing it would pass the disk cap of " + std::to_string(options_->max_disk_bytes >> 20) +
               " MiB";
      case Cut::none:
        break;
    }
    return at;
  }

  void report(const LayerFigures& figures) const {
    if (options_->on_layer) options_->on_layer(figures);
  }

  // States per block handed to a thread: enough to make the hand-out and the cap checks cheap.
  static constexpr std::uint64_t kBlock = 2048;

  const Mdp* mdp_;
  const LayeredSolveOptions* options_;
  const KeyLayout* layout_;
  int rank_;
  int ranks_;
  ScratchDirectory scratch_;
  LayeredSolution solution_;
  std::atomic<std::uint64_t> peak_memory_{0};
  std::uint64_t disk_bytes_ = 0;
  int top_ = 0;        // the last layer enumerated
  int frontier_ = -1;  // the layer that gets bounds, when cut
  Bounds start_;
  int start_choice_ = -1;
  bool has_start_ = false;
  std::vector<PolicyRecord> policy_;
};

}  // namespace

LayeredSolution solve_layered(const Mdp& mdp, const LayeredSolveOptions& options) {
  detail::require_exact_size(mdp, "solve");
  const KeyLayout layout(mdp);
  const auto run = [&]<std::size_t W>() { return LayeredSearch<W>(mdp, options, layout).run(); };
  const int words = layout.words();
  if (words <= 1) return run.template operator()<1>();
  if (words <= 2) return run.template operator()<2>();
  if (words <= 4) return run.template operator()<4>();
  return run.template operator()<kMaxExactSkeletons>();
}

}  // namespace ontime
