// The backward pass of the layered solver: the layers' values from the last to the first. Each
// layer's keys come back from disk (the last one is still in memory) and each state is valued
// from the codes its outcomes wrote on the way forward, with no search: Successors<W> gives the
// outcomes' probabilities in the order they were coded, and StateValue sums them with the next
// layer's values in the same order, with the same tie rule, as the memoised solver, so that the
// value and the first choice are its own to the bit. The layer a cut left last gets bounds
// instead (frontier.cpp); over ranks, successors owned elsewhere get their values from their
// owners (rank_exchange.cpp). The first policy_layers layers' choices are kept.
//
// Cost: per layer, its keys, 16 bytes of values and a choice per state, and the next layer's
// values; the codes are read chunk by chunk.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "ontime/solve/optimal_solver.hpp"
#include "ontime/util/parallel.hpp"
#include "solve/layered/search.hpp"

namespace ontime::layered {

template <std::size_t W>
void LayeredSearch<W>::backward(std::vector<Key> top_keys) {
  std::vector<Bounds> next_values;  // layer t + 1, by place
  for (int t = top_; t >= 0; --t) {
    const auto started = Clock::now();
    std::vector<Key> keys;
    if (t == top_) {
      keys = std::exchange(top_keys, {});
    } else {
      keys = read_keys(t, records_[static_cast<std::size_t>(t)].states);
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

// V (or its bounds) of one state after another, fed their outcomes in order and reading their
// codes: the same sums in the same order, and the same tie rule, as the memoised solver.
template <std::size_t W>
struct LayeredSearch<W>::StateValue {
  StateValue(const LayeredSearch* search_, int t_, const LayerPlaces& places_, const std::vector<Bounds>& next_values_,
             const std::vector<Bounds>& foreign_)
      : search(search_), t(t_), places(places_), next_values(next_values_), foreign(foreign_) {}
  const LayeredSearch* search;
  int t;
  const LayerPlaces& places;
  const std::vector<Bounds>& next_values;
  const std::vector<Bounds>& foreign;
  const std::uint32_t* code = nullptr;
  const double* extra = nullptr;
  const bool rewards = search->mdp_->problem().has_rewards() || search->mdp_->is_timed();  // as the forward pass
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
      // With rewards (SPEC §8) the success's reward is the next extra; else it is worth 1.
      const double worth = rewards ? probability * *extra++ : probability;
      lower_sum += worth;
      upper_sum += worth;
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

template <std::size_t W>
void LayeredSearch<W>::value_layer(const std::vector<Key>& keys, int t, const std::vector<Bounds>& next_values,
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

template <std::size_t W>
void LayeredSearch<W>::keep_policy(const std::vector<Key>& keys, const std::vector<Bounds>& values,
                                   const std::vector<int>& choices, int t) {
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (layout_->flagged(keys[i])) continue;  // copies a split counts, not states of the problem
    policy_.push_back({t, keys[i], choices[i], values[i]});
  }
}

// The members defined here, for every key width search_layers dispatches to (search.hpp).
#define ONTIME_INSTANTIATE_BACKWARD_PASS(W)                                                                            \
  template void LayeredSearch<(W)>::backward(std::vector<PackedState<(W)>>);                                           \
  template void LayeredSearch<(W)>::value_layer(const std::vector<PackedState<(W)>>&, int, const std::vector<Bounds>&, \
                                                std::vector<Bounds>&, std::vector<int>&);                              \
  template void LayeredSearch<(W)>::keep_policy(const std::vector<PackedState<(W)>>&, const std::vector<Bounds>&,      \
                                                const std::vector<int>&, int);
ONTIME_LAYERED_KEY_WIDTHS(ONTIME_INSTANTIATE_BACKWARD_PASS)
#undef ONTIME_INSTANTIATE_BACKWARD_PASS

}  // namespace ontime::layered
