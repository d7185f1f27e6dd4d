#include "ontime/ranks.hpp"

#include <algorithm>

namespace ontime {

RankUnits rank_units(std::uint64_t count, int rank, int size) noexcept {
  const auto stride = static_cast<std::uint64_t>(std::max(size, 1));
  const auto first = static_cast<std::uint64_t>(std::max(rank, 0));
  return RankUnits{first, stride, count > first ? (count - first + stride - 1) / stride : 0};
}

}  // namespace ontime
