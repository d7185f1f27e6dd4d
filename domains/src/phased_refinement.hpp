#pragma once
// Internal: what every domain's refinement shares. advance() does one bounded piece of work after
// another (work(), which the domain defines as a step of its current phase) until the motion is
// found, the attempt gives up, or the effort reaches the limit, checked between pieces (so it may
// overshoot by one).

#include <stdexcept>

#include "ontime/domains/domain.hpp"

namespace ontime::domains::detail {

class PhasedRefinement : public Refinement {
 public:
  explicit PhasedRefinement(const EffortSettings& effort) : meter_(effort) {}

  RefinementStatus advance(double limit_seconds) final {
    meter_.start_working();
    while (status_ == RefinementStatus::working && !meter_.reached(limit_seconds)) work(limit_seconds);
    meter_.stop_working();
    return status();
  }

  RefinementStatus status() const final { return status_; }
  const EffortMeter& effort() const final { return meter_; }

 protected:
  // One piece of work; `limit_seconds` for planners that run on by themselves until the limit.
  virtual void work(double limit_seconds) = 0;

  void found() noexcept { status_ = RefinementStatus::found; }
  // The attempt gives up and blames the action before (RefinementStatus::backtrack).
  void give_up() noexcept { status_ = RefinementStatus::backtrack; }
  void require_found() const {
    if (status_ != RefinementStatus::found) throw std::logic_error("the refinement has not found a motion yet");
  }

  EffortMeter meter_;

 private:
  RefinementStatus status_ = RefinementStatus::working;
};

}  // namespace ontime::domains::detail
