#include "ontime/clock.hpp"

#include <cmath>
#include <string>

#include "ontime/error.hpp"

namespace ontime {

void ManualClock::advance(double seconds) {
  if (!(seconds >= 0) || std::isinf(seconds)) {
    throw UsageError("a clock advances by a finite time >= 0 seconds (got " + std::to_string(seconds) + ")");
  }
  now_ += seconds;
}

}  // namespace ontime
