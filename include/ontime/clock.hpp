#pragma once
// The clock a live session (session.hpp) measures its time on: the steady clock on a robot, a
// manual clock in tests and simulations, where time passes only when the caller says so.

#include <chrono>

namespace ontime {

class Clock {
 public:
  virtual ~Clock() = default;
  // Seconds since some fixed origin; never decreases.
  virtual double now() const = 0;
};

// std::chrono::steady_clock in seconds: monotonic, unaffected by changes of the wall time.
class SteadyClock final : public Clock {
 public:
  double now() const override {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
};

// A clock that stands still until advanced.
class ManualClock final : public Clock {
 public:
  explicit ManualClock(double start = 0.0) noexcept : now_(start) {}
  double now() const override { return now_; }
  // Throws UsageError for a negative or non-finite step (time never runs backwards).
  void advance(double seconds);

 private:
  double now_;
};

}  // namespace ontime
