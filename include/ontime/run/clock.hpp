#pragma once
// The clock a live session (session.hpp) measures its time on: the steady clock on a robot, a
// manual clock in tests and simulations, where time passes only when the caller says so.

#include <chrono>
#include <cstdint>

namespace ontime {

// What thinking costs on a clock that models time rather than measures it, so that a report
// comes out the same to the episode on any machine and under any load: each decision is charged
// `seconds_per_decision`, plus `seconds_per_iteration` for each unit of search it ran (the
// iterations an anytime allocator such as mcts counts). A time budget for thinking becomes the
// iterations that fit in it. The defaults are of the order this project's mcts takes on the
// navigation instances on a 2-core machine (docs/tamp.md).
struct ThinkingModel {
  double seconds_per_decision = 1e-5;
  double seconds_per_iteration = 2e-6;
  // The search iterations `seconds` of thinking buy (at least 1).
  std::uint64_t iterations_within(double seconds) const noexcept;
};

class Clock {
 public:
  virtual ~Clock() = default;
  // Seconds since some fixed origin; never decreases.
  virtual double now() const = 0;
  // A clock that charges thinking by a model instead of letting real time pass: the model;
  // nullptr (the default) for clocks whose time passes by itself.
  virtual const ThinkingModel* thinking_model() const noexcept { return nullptr; }
  // On a clock with a thinking model: a decision that ran `iterations` units of search was made;
  // the clock moves on by its cost. Others ignore it.
  virtual void charge_thinking(std::uint64_t iterations) const { (void)iterations; }
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
  // A clock that reads `start` seconds until advanced.
  explicit ManualClock(double start = 0.0) noexcept : now_(start) {}
  double now() const override { return now_; }
  // Throws UsageError for a negative or non-finite step (time never runs backwards).
  void advance(double seconds);

 private:
  double now_;
};

}  // namespace ontime
