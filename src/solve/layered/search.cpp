// The layered search's driver: the dispatch to the key width an instance needs, and the results
// every rank returns. LayeredSearch<W>::run (search.hpp) starts from the start state (blanked and
// reduced by the tolerance as a successor is), runs the forward and the backward pass, and
// `finish` gathers what the ranks found: the start's value and first choice (from the rank that
// owns the start), the peaks of memory and disk (the largest over ranks), the dropped outcomes
// (their sum) and the policy's first layers (sorted by layer, then key, so that every rank and
// every thread count give the same list), with the start's own dropped groups added to the
// interval.

#include "solve/layered/search.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/byte_packing.hpp"
#include "ontime/util/error.hpp"
#include "solve/expectimax.hpp"

namespace ontime::layered {

template <std::size_t W>
void LayeredSearch<W>::finish() {
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
    State state = mdp_->start();  // sized for the skeletons and the restore values
    if (mdp_->is_timed()) {
      detail::CompactTimedState compact;
      layout_->decode(record.key, record.layer, compact);
      detail::expanded(compact, state);
    } else if (mdp_->has_backtracking()) {
      detail::CompactBacktrackState compact;
      layout_->decode(record.key, record.layer, compact);
      detail::expanded(compact, state);
    } else {
      CompactState compact;
      layout_->decode(record.key, record.layer, compact);
      detail::expanded(compact, state);
    }
    solution_.policy.push_back(
        {std::move(state), record.choice, record.value.lower, exact ? record.value.lower : record.value.upper});
  }
}

// The members defined here, for every key width search_layers dispatches to (search.hpp).
#define ONTIME_INSTANTIATE_SEARCH(W) template void LayeredSearch<W>::finish();
ONTIME_LAYERED_KEY_WIDTHS(ONTIME_INSTANTIATE_SEARCH)
#undef ONTIME_INSTANTIATE_SEARCH

namespace {

template <std::size_t W>
LayeredSolution run_search(const Mdp& mdp, const LayeredSolveOptions& options, bool flag, const WeakCluster* weak) {
  const KeyLayout layout(mdp, flag);
  std::optional<ValueBounds> bounds;
  if (options.tolerance > 0) bounds.emplace(mdp);  // ResourceLimitError when the tables are too large
  return LayeredSearch<W>(mdp, options, layout, bounds ? &*bounds : nullptr, weak).run();
}

}  // namespace

LayeredSolution search_layers(const Mdp& mdp, const LayeredSolveOptions& options, bool flag, const WeakCluster* weak) {
  const int words = KeyLayout(mdp, flag).words();
  if (words > static_cast<int>(kMaxExactSkeletons) + 1) {
    // Only restore values (backtracking's, or timed slots'), with a deadline in the tens of
    // thousands, get here.
    throw UsageError("solve: a state of " + mdp.problem().name() + " needs " + std::to_string(words) +
                     " words of key, above the layered solver's " + std::to_string(kMaxExactSkeletons + 1) +
                     "; the memoised solver (--method memoised) takes it");
  }
  if (words <= 1) return run_search<1>(mdp, options, flag, weak);
  if (words <= 2) return run_search<2>(mdp, options, flag, weak);
  if (words <= 4) return run_search<4>(mdp, options, flag, weak);
  if (words <= kMaxExactSkeletons) return run_search<kMaxExactSkeletons>(mdp, options, flag, weak);
  return run_search<kMaxExactSkeletons + 1>(mdp, options, flag, weak);  // a split's flag past 16 words
}

}  // namespace ontime::layered
