#pragma once
// A hidden world on a manual clock that one step of effort advances by exactly `slices` slices of
// the problem's step (one by default): with instant decisions, a live session's reports then take
// exactly the model's steps (tests of live sessions against the model).

#include <cstdint>

#include "ontime/model/problem.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/run/world.hpp"

namespace ontime::testing {

class SlicedWorld final : public World {
 public:
  explicit SlicedWorld(const Problem& problem, double slices = 1)
      : world_(problem, 0), slice_(slices * problem.step_seconds()) {}
  void begin_episode(std::uint64_t seed) override { world_.begin_episode(seed); }
  Observation step(int action, Steps spent) override {
    clock_.advance(slice_);
    return world_.step(action, spent);
  }
  const Clock* clock() const noexcept override { return &clock_; }

 private:
  HiddenWorld world_;
  double slice_;
  ManualClock clock_;
};

}  // namespace ontime::testing
