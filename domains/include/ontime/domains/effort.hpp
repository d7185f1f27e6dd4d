#pragma once
// Planner effort: what one step of the allocation MDP buys. Two units (docs/domains.md):
//
// - collision checks (deterministic): effort is the number of collision checks the planner has
//   made, converted to seconds at a fixed nominal rate (`checks_per_second`). The same seed gives
//   the same planning times, logs and instances on any machine and for any thread count.
// - wall clock: effort is the real time spent refining, on this machine. What a robot lives by,
//   but it varies from run to run and with the load of the machine.
//
// Both count the checks; only the seconds reported differ.

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

namespace ontime::domains {

enum class EffortUnit { collision_checks, wall_clock };

// "checks" or "wall"; throws std::invalid_argument for another name.
EffortUnit parse_effort_unit(std::string_view name);
std::string_view effort_unit_name(EffortUnit unit) noexcept;

struct EffortSettings {
  EffortUnit unit = EffortUnit::collision_checks;
  double checks_per_second = 1000.0;  // nominal speed of the collision checker (checks unit)
};

// Counts the effort of one refinement. Not thread-safe: one meter per refinement.
class EffortMeter {
 public:
  // A meter at zero effort, counting in the unit of `settings`.
  explicit EffortMeter(EffortSettings settings) : settings_(settings) {}

  // Counts one collision check.
  void count_check() noexcept { ++checks_; }
  // Work that is not a collision check but costs as much as `checks` of them (an IK solve).
  void count_checks(std::uint64_t checks) noexcept { checks_ += checks; }
  std::uint64_t checks() const noexcept { return checks_; }

  // Effort spent so far, in seconds of the selected unit.
  double seconds() const;

  // Marks the start and end of a period of work (wall-clock time is counted only inside).
  void start_working();
  void stop_working();

  // True once the effort reaches `limit_seconds`. In the checks unit the limit is rounded to a
  // whole number of checks, so the comparison is exact.
  bool reached(double limit_seconds) const;

  // The unit and the checker's nominal speed.
  const EffortSettings& settings() const noexcept { return settings_; }

 private:
  using Clock = std::chrono::steady_clock;
  EffortSettings settings_;
  std::uint64_t checks_ = 0;
  double wall_seconds_ = 0;  // completed periods of work
  bool working_ = false;
  Clock::time_point since_{};
};

}  // namespace ontime::domains
