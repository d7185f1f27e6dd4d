#include "ontime/ranks.hpp"

#include <algorithm>

namespace ontime {

UnitShare unit_share(std::uint64_t count, int rank, int size) noexcept {
  const auto ranks = static_cast<std::uint64_t>(size > 0 ? size : 1);
  const auto r = static_cast<std::uint64_t>(rank);
  // The first count % ranks ranks take one unit more.
  const std::uint64_t base = count / ranks, extra = count % ranks;
  const std::uint64_t begin = r * base + std::min(r, extra);
  return UnitShare{begin, begin + base + (r < extra ? 1 : 0)};
}

}  // namespace ontime
