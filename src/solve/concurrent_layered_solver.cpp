// `solve_concurrent_layered` (include/ontime/solve/concurrent_layered_solver.hpp): the levels of the
// acting-while-planning MDP built forward, valued backward.
//
// A level's states lie in one array of W words each (W = 4 + 2K + A, the state's words); a state's
// outcomes that are not settled are numbered, in walk order, by their places in the next level
// (codes), indexed per block of states so that threads can value blocks apart. Once a level's
// codes are written, its states and codes go to the scratch directory (the plan-first layered
// solver's ScratchDirectory and ScratchFile) and come back for the backward pass.

#include "ontime/solve/concurrent_layered_solver.hpp"

#include <absl/container/flat_hash_set.h>
#include <absl/hash/hash.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/solve/concurrent_value_bounds.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/parallel.hpp"
#include "ontime/util/ranks.hpp"
#include "solve/layered/storage.hpp"
#include "solve/scratch_directory.hpp"

namespace ontime {
// Named rather than anonymous: the library is built in unity batches, where another file's
// anonymous namespace may hold the same names.
namespace concurrent_levels {

using Clock = std::chrono::steady_clock;
using Move = ConcurrentMdp::Move;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// States per block (a thread's unit of work, and the unit of the codes' index) and blocks per
// chunk (between two merges into the next level's table and two checks of the caps).
constexpr std::uint64_t kBlock = 512;
constexpr std::uint64_t kChunkBlocks = 64;

// A place in a level is 32 bits.
constexpr std::uint64_t kMaxPlaces = std::numeric_limits<std::uint32_t>::max();

// The keys of the level being built: W words each in one array, and a hash set of their places
// that hashes and compares the words they point to.
class KeyTable {
 public:
  explicit KeyTable(std::size_t width) : width_(width), set_(0, Hash{this}, Equal{this}) {}
  ~KeyTable() = default;
  KeyTable(const KeyTable&) = delete;
  KeyTable& operator=(const KeyTable&) = delete;
  KeyTable(KeyTable&&) = delete;
  KeyTable& operator=(KeyTable&&) = delete;

  // The place of `key` (W words), inserted when new.
  std::uint32_t insert(const std::uint16_t* key) {
    if (size() >= kMaxPlaces) {
      throw ResourceLimitError("the layered solver met a level of more than " + std::to_string(kMaxPlaces) +
                               " states, more than its places can name");
    }
    words_.insert(words_.end(), key, key + width_);
    const auto [found, inserted] = set_.insert(static_cast<std::uint32_t>(size() - 1));
    if (!inserted) words_.resize(words_.size() - width_);
    return *found;
  }
  std::uint64_t size() const noexcept { return words_.size() / width_; }
  // What it holds in memory: the keys' array and the set's slots and control bytes.
  std::uint64_t bytes() const noexcept {
    return words_.capacity() * sizeof(std::uint16_t) + set_.capacity() * (sizeof(std::uint32_t) + 1);
  }
  // The keys, in the order they were placed; the table is empty after.
  std::vector<std::uint16_t> release() {
    set_.clear();
    return std::move(words_);
  }

 private:
  std::string_view view(std::uint32_t place) const noexcept {
    return {reinterpret_cast<const char*>(words_.data() + place * width_), width_ * sizeof(std::uint16_t)};
  }
  struct Hash {
    const KeyTable* table;
    std::size_t operator()(std::uint32_t place) const { return absl::Hash<std::string_view>{}(table->view(place)); }
  };
  struct Equal {
    const KeyTable* table;
    bool operator()(std::uint32_t a, std::uint32_t b) const { return table->view(a) == table->view(b); }
  };

  std::size_t width_;
  std::vector<std::uint16_t> words_;
  absl::flat_hash_set<std::uint32_t, Hash, Equal> set_;
};

// One level: its states, and the places of their outcomes that are not settled. On disk between
// the passes (`states` and `codes` empty then), but for the last level enumerated.
struct Level {
  std::uint64_t count = 0;                 // states
  std::vector<std::uint16_t> states;       // W words each
  std::vector<std::uint32_t> codes;        // places in the next level, in walk order
  std::vector<std::uint64_t> block_codes;  // per block of kBlock states: its first code; then the end
};

// Why the forward pass ended early.
enum class Cut { none, states, memory, disk, stop };

const char* describe(Cut cut) {
  switch (cut) {
    case Cut::states:
      return "the state cap";
    case Cut::memory:
      return "the memory cap";
    case Cut::disk:
      return "the disk cap";
    case Cut::stop:
      return "the stop condition";
    case Cut::none:
      break;
  }
  return "";
}

using Interval = ConcurrentValueBounds::Interval;

class LayeredConcurrentSearch {
 public:
  LayeredConcurrentSearch(const ConcurrentMdp& mdp, const LayeredSolveOptions& options)
      : mdp_(mdp),
        options_(options),
        width_(mdp.start().size()),
        merge_(mdp.merges_backlogs()),
        scratch_(options.scratch_directory, 0, options.remove_scratch_on_signal, options.on_stale_scratch) {}

  ConcurrentSolution run() {
    const ConcurrentState start = mdp_.start();
    if (const std::optional<double> settled = settled_value(mdp_, start)) {
      solution_.lower = solution_.upper = *settled;
      solution_.exact = true;
      return std::move(solution_);
    }
    ConcurrentState key = start;
    if (merge_) mdp_.merge_backlogs(key);
    levels_.push_back(Level{.count = 1, .states = key, .codes = {}, .block_codes = {}});
    solution_.solved = 1;
    forward();
    backward();
    return std::move(solution_);
  }

 private:
  ConcurrentState state_at(const Level& level, std::uint64_t index) const {
    const auto* words = level.states.data() + index * width_;
    return {words, words + width_};
  }

  // A level's states and codes to its scratch files, and back.
  void write_level(int n, Level& level) {
    for (const bool codes : {false, true}) {
      layered::ScratchFile file(scratch_.file(n, codes ? "codes" : "states"), n, "wb");
      if (codes) {
        file.write(level.codes.data(), level.codes.size());
      } else {
        file.write(level.states.data(), level.states.size());
      }
      file.close();
    }
    disk_bytes_ += level.codes.size() * sizeof(std::uint32_t) + level.states.size() * sizeof(std::uint16_t);
    solution_.peak_disk_bytes = std::max(solution_.peak_disk_bytes, disk_bytes_);
    // Released, not just emptied (assigning {} would keep the capacity).
    std::vector<std::uint16_t>().swap(level.states);
    std::vector<std::uint32_t>().swap(level.codes);
  }
  void read_level(int n, Level& level, bool with_codes) {
    level.states.resize(level.count * width_);
    layered::ScratchFile states(scratch_.file(n, "states"), n, "rb");
    states.read(level.states.data(), level.states.size());
    if (!with_codes) return;
    level.codes.resize(level.block_codes.back());
    layered::ScratchFile codes(scratch_.file(n, "codes"), n, "rb");
    codes.read(level.codes.data(), level.codes.size());
  }
  void remove_level_files(int n) {
    std::error_code ignored;
    for (const char* what : {"states", "codes"}) {
      const std::filesystem::path file = scratch_.file(n, what);
      const std::uintmax_t size = std::filesystem::file_size(file, ignored);
      if (std::filesystem::remove(file, ignored)) disk_bytes_ -= std::min<std::uint64_t>(disk_bytes_, size);
    }
  }

  // The keys of the successors not settled of the states [begin, end) of `level`, in walk order
  // (W words each).
  void expand(const Level& level, std::uint64_t begin, std::uint64_t end, std::vector<std::uint16_t>& keys) const {
    ConcurrentState key;
    const auto visit = [&](const ConcurrentState& next) {
      if (settled_value(mdp_, next)) return 0.0;
      if (merge_) {
        key = next;
        mdp_.merge_backlogs(key);
        keys.insert(keys.end(), key.begin(), key.end());
      } else {
        keys.insert(keys.end(), next.begin(), next.end());
      }
      return 0.0;
    };
    for (std::uint64_t i = begin; i < end; ++i) {
      const ConcurrentState state = state_at(level, i);
      for (const Move& move : mdp_.useful_moves(state)) move_value(mdp_, state, move, visit);
    }
  }

  // Why the forward pass must end now, if it must: a cap that `states` enumerated, `memory` held or
  // `disk` written passes, or the stop condition.
  Cut cut_by(std::uint64_t states, std::uint64_t memory, std::uint64_t disk) const {
    if (options_.max_states > 0 && states > options_.max_states) return Cut::states;
    if (options_.max_memory_bytes > 0 && memory > options_.max_memory_bytes) return Cut::memory;
    if (options_.max_disk_bytes > 0 && disk > options_.max_disk_bytes) return Cut::disk;
    if (options_.stop && options_.stop()) return Cut::stop;
    return Cut::none;
  }

  // Builds the levels until one has no successor left to enumerate, or a cap or the stop cuts
  // the pass (then the last level built is the frontier).
  void forward() {
    for (std::size_t n = 0;; ++n) {
      const auto started = Clock::now();
      Level& level = levels_[n];
      const std::uint64_t states = level.count;
      const std::uint64_t blocks = (states + kBlock - 1) / kBlock;
      KeyTable table(width_);
      std::vector<std::uint32_t> codes;
      std::vector<std::uint64_t> block_codes(blocks + 1, 0);
      std::vector<std::vector<std::uint16_t>> outputs(kChunkBlocks);  // per block of a chunk: its successors' keys
      Cut cut = Cut::none;
      for (std::uint64_t first = 0; first < blocks && cut == Cut::none; first += kChunkBlocks) {
        const std::uint64_t chunk = std::min(kChunkBlocks, blocks - first);
        for_each_block(chunk, options_.threads, 1, [&](unsigned) {
          return [&](std::uint64_t begin, std::uint64_t end) {
            for (std::uint64_t b = begin; b < end; ++b) {
              outputs[b].clear();
              const std::uint64_t from = (first + b) * kBlock;
              expand(level, from, std::min(states, from + kBlock), outputs[b]);
            }
          };
        });
        std::uint64_t scratch = 0;
        for (std::uint64_t b = 0; b < chunk; ++b) {
          const std::vector<std::uint16_t>& keys = outputs[b];
          scratch += keys.capacity() * sizeof(std::uint16_t);
          block_codes[first + b] = codes.size();
          for (std::size_t at = 0; at < keys.size(); at += width_) codes.push_back(table.insert(keys.data() + at));
        }
        // Capacities: a vector that grows holds its old and its new array for a while.
        const std::uint64_t memory = level.states.capacity() * sizeof(std::uint16_t) + table.bytes() +
                                     codes.capacity() * sizeof(std::uint32_t) + scratch;
        solution_.peak_memory_bytes = std::max(solution_.peak_memory_bytes, memory);
        // The level's files, once written, take its states and codes.
        const std::uint64_t disk =
            disk_bytes_ + level.states.size() * sizeof(std::uint16_t) + codes.size() * sizeof(std::uint32_t);
        // The start's successors are always enumerated, so that the first move is one the
        // backward pass chooses.
        if (n > 0) cut = cut_by(solution_.solved + table.size(), memory, disk);
      }
      if (cut != Cut::none) {
        solution_.frontier_layer = static_cast<int>(n);
        solution_.stopped_by = describe(cut);
        report(LayerFigures{.layer = static_cast<int>(n), .states = states, .forward_seconds = seconds_since(started)});
        return;
      }
      block_codes[blocks] = codes.size();
      level.codes = std::move(codes);
      level.block_codes = std::move(block_codes);
      Level next{.count = 0, .states = table.release(), .codes = {}, .block_codes = {}};
      next.count = next.states.size() / width_;
      if (next.count == 0) {  // the last level: its states stay for the backward pass
        report(LayerFigures{.layer = static_cast<int>(n), .states = states, .forward_seconds = seconds_since(started)});
        return;
      }
      write_level(static_cast<int>(n), level);
      report(LayerFigures{.layer = static_cast<int>(n), .states = states, .forward_seconds = seconds_since(started)});
      solution_.solved += next.count;
      levels_.push_back(std::move(next));
    }
  }

  // Values the states of level n from the next level's intervals (`exact`: their lower ends only,
  // each upper end the same); the start's move too, at level 0.
  void value_level(std::size_t n, const std::vector<Interval>& next, bool exact, std::vector<Interval>& values) {
    const Level& level = levels_[n];
    const std::uint64_t states = level.count;
    values.assign(states, Interval{});
    const std::uint64_t blocks = (states + kBlock - 1) / kBlock;
    for_each_block(blocks, options_.threads, 1, [&](unsigned) {
      return [&](std::uint64_t begin, std::uint64_t end) {
        struct MoveValue {
          Move move;
          Interval q;
        };
        std::vector<MoveValue> moves;
        for (std::uint64_t b = begin; b < end; ++b) {
          std::uint64_t code = level.block_codes[b];
          const std::uint64_t last = std::min(states, (b + 1) * kBlock);
          for (std::uint64_t i = b * kBlock; i < last; ++i) {
            const ConcurrentState state = state_at(level, i);
            moves.clear();
            for (const Move& move : mdp_.useful_moves(state)) {
              const std::uint64_t from = code;
              MoveValue value{.move = move, .q = {}};
              // The memoised solver's sum: each outcome's probability times its successor's value.
              value.q.lower = move_value(mdp_, state, move, [&](const ConcurrentState& successor) {
                if (const std::optional<double> settled = settled_value(mdp_, successor)) return *settled;
                return next[level.codes[code++]].lower;
              });
              if (exact) {
                value.q.upper = value.q.lower;
              } else {
                code = from;
                value.q.upper = move_value(mdp_, state, move, [&](const ConcurrentState& successor) {
                  if (const std::optional<double> settled = settled_value(mdp_, successor)) return *settled;
                  return next[level.codes[code++]].upper;
                });
              }
              moves.push_back(value);
            }
            // The memoised solver's tie rule, on the lower ends.
            double best = -1.0, upper = 0.0;
            for (const MoveValue& value : moves) {
              best = std::max(best, value.q.lower);
              upper = std::max(upper, value.q.upper);
            }
            for (const MoveValue& value : moves) {
              if (value.q.lower >= best - ConcurrentSolver::kTieTolerance) {
                values[i] = {value.q.lower, exact ? value.q.lower : upper};
                if (n == 0) solution_.first = value.move;
                break;
              }
            }
          }
        }
      };
    });
  }

  // The frontier's states: ConcurrentValueBounds' intervals, widened against rounding unless
  // their ends meet.
  void bound_level(std::size_t n, std::vector<Interval>& values) {
    const Level& level = levels_[n];
    const std::uint64_t states = level.count;
    values.assign(states, Interval{});
    for_each_block(states, options_.threads, kBlock, [&](unsigned) {
      return [&, bounds = ConcurrentValueBounds(mdp_)](std::uint64_t begin, std::uint64_t end) mutable {
        for (std::uint64_t i = begin; i < end; ++i) {
          const ConcurrentValueBounds::Interval interval = bounds.bounds(state_at(level, i));
          values[i] = {interval.lower, interval.upper};
          if (interval.lower < interval.upper) {
            values[i].lower = std::max(0.0, interval.lower - ConcurrentSearch::kBoundSlack);
            values[i].upper = interval.upper + ConcurrentSearch::kBoundSlack;
          }
        }
      };
    });
  }

  void backward() {
    const bool exact = solution_.frontier_layer < 0;
    std::vector<Interval> next, values;
    for (std::size_t n = levels_.size(); n-- > 0;) {
      const auto started = Clock::now();
      Level& level = levels_[n];
      // Every level but the last enumerated (frontier or not) comes back from its files.
      if (level.states.empty()) read_level(static_cast<int>(n), level, static_cast<int>(n) != solution_.frontier_layer);
      if (static_cast<int>(n) == solution_.frontier_layer) {
        bound_level(n, values);
      } else {
        value_level(n, next, exact, values);
      }
      const std::uint64_t memory = level.states.size() * sizeof(std::uint16_t) +
                                   level.codes.size() * sizeof(std::uint32_t) +
                                   (values.size() + next.size()) * sizeof(Interval);
      solution_.peak_memory_bytes = std::max(solution_.peak_memory_bytes, memory);
      const std::uint64_t states = level.count;
      level = Level{};  // valued: no longer needed
      remove_level_files(static_cast<int>(n));
      std::swap(next, values);
      LayerFigures figures{.layer = static_cast<int>(n), .states = states, .backward = true};
      figures.backward_seconds = seconds_since(started);
      report(figures);
    }
    solution_.lower = next.front().lower;
    solution_.upper = next.front().upper;
    solution_.exact = exact;
  }

  void report(const LayerFigures& figures) {
    // The figures of a level: its forward entry, completed by the backward pass.
    if (!figures.backward) {
      solution_.layers.push_back(figures);
    } else {
      LayerFigures& entry = solution_.layers[static_cast<std::size_t>(figures.layer)];
      entry.backward_seconds = figures.backward_seconds;
      entry.backward = true;
    }
    if (options_.on_layer) options_.on_layer(figures);
  }

  const ConcurrentMdp& mdp_;
  const LayeredSolveOptions& options_;
  std::size_t width_;
  bool merge_;
  ScratchDirectory scratch_;
  std::uint64_t disk_bytes_ = 0;  // the levels' files
  std::vector<Level> levels_;
  ConcurrentSolution solution_;
};

// What the plan-first layered solver takes that this one does not: UsageError naming it.
void check_concurrent_layered_options(const LayeredSolveOptions& options) {
  const std::string rule = " (acting while planning, SPEC §10, is solved level by level in one process, exactly)";
  if (options.tolerance > 0) throw UsageError("solve: a tolerance does not apply" + rule);
  if (options.split == SplitMode::always) throw UsageError("solve: a split does not apply" + rule);
  if (options.policy_layers > 0) throw UsageError("solve: a policy file is not written" + rule);
  if (options.ranks != nullptr && options.ranks->size() > 1) throw UsageError("solve: no MPI ranks" + rule);
}

}  // namespace concurrent_levels

ConcurrentSolution solve_concurrent_layered(const ConcurrentMdp& mdp, const LayeredSolveOptions& options) {
  concurrent_levels::check_concurrent_layered_options(options);
  return concurrent_levels::LayeredConcurrentSearch(mdp, options).run();
}

}  // namespace ontime
