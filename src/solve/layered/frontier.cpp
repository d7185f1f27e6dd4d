// Where the forward pass of the layered solver stopped, and what the states there are worth.
// When a cap (states, memory, disk) or the stop ends the forward pass at layer T, the states of
// layer T get an interval instead of a value: ValueBounds's commit policy below (a real
// policy, so the lower end stays achievable) and its clairvoyant relaxation above, or [0, 1]
// (0 where nothing can succeed) where even those tables are too large. In a split, a state that has not stepped on the
// bounded subtrees yet also gets their share: committing to them fresh is a policy, and the
// upper end takes both parts as if each had all the time left (docs/theory.md has the proofs).
// `describe` says in words which cap ended the pass, and where.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/parallel.hpp"
#include "solve/layered/search.hpp"

namespace ontime::layered {

template <std::size_t W>
void LayeredSearch<W>::value_frontier(const std::vector<Key>& keys, int t, std::vector<Bounds>& values,
                                      std::vector<int>& choices) {
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
      detail::CompactBacktrackState back_state;
      detail::CompactTimedState timed_state;
      const auto bound = [&](const auto& decoded, std::uint64_t i) {
        if (bounds != nullptr) {
          values[i] = {bounds->lower(decoded), bounds->upper(decoded)};
          choices[i] = bounds->lower_choice(decoded);
        } else {
          values[i] = {0.0, mdp_->any_can_succeed(decoded) ? mdp_->problem().max_reward() : 0.0};
        }
      };
      for (std::uint64_t i = begin; i < end; ++i) {
        if (mdp_->is_timed()) {
          layout_->decode(keys[i], t, timed_state);
          bound(timed_state, i);
        } else if (mdp_->has_backtracking()) {
          layout_->decode(keys[i], t, back_state);
          bound(back_state, i);
        } else {
          layout_->decode(keys[i], t, state);
          bound(state, i);
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

template <std::size_t W>
std::string LayeredSearch<W>::describe(Cut cut, int t) const {
  std::string at =
      "the forward pass stopped at layer " + std::to_string(t) + " (" + std::to_string(solution_.states) + " states)";
  switch (cut) {
    case Cut::stop:
      return at + " at the caller's request";
    case Cut::states:
      return at + ": the next layer would pass the cap of " + std::to_string(options_->max_states) + " states";
    case Cut::memory:
      return at + ": the next layer would pass the memory cap of " + std::to_string(options_->max_memory_bytes >> 20) +
             " MiB";
    case Cut::disk:
      return at + ": its scratch files would pass the disk cap of " + std::to_string(options_->max_disk_bytes >> 20) +
             " MiB";
    case Cut::none:
      break;
  }
  return at;
}

// The members defined here, for every key width search_layers dispatches to (search.hpp).
#define ONTIME_INSTANTIATE_FRONTIER(W)                                                                              \
  template void LayeredSearch<(W)>::value_frontier(const std::vector<PackedState<(W)>>&, int, std::vector<Bounds>&, \
                                                   std::vector<int>&);                                              \
  template std::string LayeredSearch<(W)>::describe(Cut, int) const;
ONTIME_LAYERED_KEY_WIDTHS(ONTIME_INSTANTIATE_FRONTIER)
#undef ONTIME_INSTANTIATE_FRONTIER

}  // namespace ontime::layered
