#include "ontime/domains/effort.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime::domains {

EffortUnit parse_effort_unit(std::string_view name) {
  if (name == "checks") return EffortUnit::collision_checks;
  if (name == "wall") return EffortUnit::wall_clock;
  static const std::string kKnown[] = {"checks", "wall"};
  throw unknown_name_error("effort unit", name, kKnown);
}

std::string_view effort_unit_name(EffortUnit unit) noexcept {
  return unit == EffortUnit::collision_checks ? "checks" : "wall";
}

double EffortMeter::seconds() const {
  if (settings_.unit == EffortUnit::collision_checks) {
    return static_cast<double>(checks_) / settings_.checks_per_second;
  }
  return wall_seconds_ + (working_ ? std::chrono::duration<double>(Clock::now() - since_).count() : 0.0);
}

void EffortMeter::start_working() {
  if (working_) return;
  working_ = true;
  since_ = Clock::now();
}

void EffortMeter::stop_working() {
  if (!working_) return;
  wall_seconds_ += std::chrono::duration<double>(Clock::now() - since_).count();
  working_ = false;
}

bool EffortMeter::reached(double limit_seconds) const {
  if (settings_.unit == EffortUnit::collision_checks) {
    return static_cast<double>(checks_) >= std::round(limit_seconds * settings_.checks_per_second);
  }
  return seconds() >= limit_seconds;
}

}  // namespace ontime::domains
