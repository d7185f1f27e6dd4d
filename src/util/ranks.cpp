#include "ontime/util/ranks.hpp"

#include <algorithm>

#include "ontime/util/byte_packing.hpp"
#include "ontime/util/error.hpp"

namespace ontime {

RankUnits rank_units(std::uint64_t count, int rank, int size) noexcept {
  const auto stride = static_cast<std::uint64_t>(std::max(size, 1));
  const auto first = static_cast<std::uint64_t>(std::max(rank, 0));
  return RankUnits{first, stride, count > first ? (count - first + stride - 1) / stride : 0};
}

std::vector<std::string> Ranks::all_to_all(const std::vector<std::string>& parts) const {
  if (parts.size() != static_cast<std::size_t>(size())) {
    throw UsageError("Ranks::all_to_all: " + std::to_string(parts.size()) + " parts for " + std::to_string(size()) +
                     " ranks");
  }
  BytePacker packer;
  for (const std::string& part : parts) packer.put_string(part);
  const std::vector<std::string> gathered = all_gather(packer.bytes());
  std::vector<std::string> received(gathered.size());
  for (std::size_t from = 0; from < gathered.size(); ++from) {
    ByteUnpacker unpacker(gathered[from]);
    for (int to = 0; to <= rank(); ++to) received[from] = unpacker.get_string();
  }
  return received;
}

}  // namespace ontime
