// What the ranks of a layered solve exchange, each a collective every rank calls in the same
// order (all_gather, all_to_all of Ranks): the sums and maxima of their counts, the cut that ends
// the forward pass (the first rank's reason, so that every rank stops at the same layer) and, in
// the backward pass, the values of the successors a rank's states have on other ranks, asked of
// their owners by place. With one process each is a no-op that returns its own argument.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "ontime/util/byte_packing.hpp"
#include "solve/layered/search.hpp"

namespace ontime::layered {

template <std::size_t W>
std::vector<std::string> LayeredSearch<W>::gather(const std::string& bytes) const {
  return ranks_ == 1 ? std::vector<std::string>{bytes} : options_->ranks->all_gather(bytes);
}

template <std::size_t W>
std::uint64_t LayeredSearch<W>::sum_over_ranks(std::uint64_t count) const {
  if (ranks_ == 1) return count;
  BytePacker packer;
  packer.put(count);
  std::uint64_t total = 0;
  for (const std::string& part : gather(packer.bytes())) total += ByteUnpacker(part).get<std::uint64_t>();
  return total;
}

template <std::size_t W>
std::uint64_t LayeredSearch<W>::max_over_ranks(std::uint64_t count) const {
  if (ranks_ == 1) return count;
  BytePacker packer;
  packer.put(count);
  std::uint64_t most = 0;
  for (const std::string& part : gather(packer.bytes())) most = std::max(most, ByteUnpacker(part).get<std::uint64_t>());
  return most;
}

template <std::size_t W>
Cut LayeredSearch<W>::first_cut(Cut mine) const {
  if (ranks_ == 1) return mine;
  BytePacker packer;
  packer.put(static_cast<std::uint8_t>(mine));
  for (const std::string& part : gather(packer.bytes())) {
    const auto cut = static_cast<Cut>(ByteUnpacker(part).get<std::uint8_t>());
    if (cut != Cut::none) return cut;
  }
  return Cut::none;
}

template <std::size_t W>
std::vector<Bounds> LayeredSearch<W>::fetch_foreign_values(const LayerRecord& record,
                                                           const std::vector<Bounds>& next_values) {
  if (ranks_ == 1) return {};
  std::vector<std::string> requests(static_cast<std::size_t>(ranks_));
  for (std::size_t r = 0; r < requests.size(); ++r) {
    requests[r].assign(reinterpret_cast<const char*>(record.foreign[r].data()),
                       record.foreign[r].size() * sizeof(std::uint32_t));
  }
  std::vector<std::string> answers;
  for (const std::string& request : options_->ranks->all_to_all(requests)) {
    std::string answer(request.size() / sizeof(std::uint32_t) * sizeof(Bounds), '\0');
    for (std::size_t i = 0; i < request.size() / sizeof(std::uint32_t); ++i) {
      std::uint32_t at = 0;
      std::memcpy(&at, request.data() + i * sizeof(at), sizeof(at));
      const Bounds value = next_values[record.next.base[at & (shards_ - 1)] + (at >> shard_bits_)];
      std::memcpy(answer.data() + i * sizeof(Bounds), &value, sizeof(Bounds));
    }
    answers.push_back(std::move(answer));
  }
  const std::vector<std::string> replies = options_->ranks->all_to_all(answers);
  // Entries were numbered in the order they were first met, owners interleaved: each owner's
  // answers come in its list's order.
  std::vector<Bounds> values;
  values.reserve(record.foreign_rank.size());
  std::vector<std::size_t> next(static_cast<std::size_t>(ranks_), 0);
  for (const std::uint16_t owner : record.foreign_rank) {
    const std::size_t r = owner;
    Bounds value;
    std::memcpy(&value, replies[r].data() + next[r] * sizeof(Bounds), sizeof(Bounds));
    ++next[r];
    values.push_back(value);
  }
  return values;
}

// The members defined here, for every key width search_layers dispatches to (search.hpp).
#define ONTIME_INSTANTIATE_RANK_EXCHANGE(W)                                             \
  template std::vector<std::string> LayeredSearch<W>::gather(const std::string&) const; \
  template std::uint64_t LayeredSearch<W>::sum_over_ranks(std::uint64_t) const;         \
  template std::uint64_t LayeredSearch<W>::max_over_ranks(std::uint64_t) const;         \
  template Cut LayeredSearch<W>::first_cut(Cut) const;                                  \
  template std::vector<Bounds> LayeredSearch<W>::fetch_foreign_values(const LayerRecord&, const std::vector<Bounds>&);
ONTIME_LAYERED_KEY_WIDTHS(ONTIME_INSTANTIATE_RANK_EXCHANGE)
#undef ONTIME_INSTANTIATE_RANK_EXCHANGE

}  // namespace ontime::layered
