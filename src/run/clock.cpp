#include "ontime/run/clock.hpp"

#include <cmath>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime {

std::uint64_t ThinkingModel::iterations_within(double seconds) const noexcept {
  const double fit = std::floor((seconds - seconds_per_decision) / seconds_per_iteration);
  if (!(fit >= 1)) return 1;
  return fit >= 1e15 ? std::uint64_t{1'000'000'000'000'000} : static_cast<std::uint64_t>(fit);
}

void ManualClock::advance(double seconds) {
  if (!(seconds >= 0) || std::isinf(seconds)) {
    throw UsageError("a clock advances by a finite time >= 0 seconds (got " + std::to_string(seconds) + ")");
  }
  now_ += seconds;
}

}  // namespace ontime
