#pragma once
// Named counters that an allocator or a world reports about its own work (search iterations,
// tree sizes, refinements started, ...), so that the episode runner, the CLI's JSON output
// and the Python bindings can report any component's figures without knowing its kind.
//
// Each counter says how two values merge: summed (work done, over episodes and threads) or
// the larger kept (peaks). Counters keep the order in which they were first added, so a
// report lists them the same way every time.

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace ontime {

// Sums that do not depend on the order they are added in (threads, ranks): each value is rounded
// to a whole number of units of 2^-32 (2.3e-10) and the whole numbers are added, exactly. Used
// for per-episode figures (regret, rewards) summed over episodes.
inline constexpr double kSumUnit = 0x1p-32;
inline double sum_units(double value) { return std::round(value / kSumUnit); }

// The mean of `count` values from the sums of their units and of their squares' units, and the
// 95% half-width of the mean (1.96 standard errors, normal approximation).
struct MeanInterval {
  double mean = 0;
  double ci95 = 0;
};
// The mean and half-width above from the sums (of sum_units); zeros for a count below 1.
inline MeanInterval mean_interval_of_units(double units, double square_units, double count) {
  MeanInterval out;
  if (!(count >= 1)) return out;
  out.mean = units * kSumUnit / count;
  const double variance = std::max(0.0, square_units * kSumUnit / count - out.mean * out.mean);
  out.ci95 = 1.96 * std::sqrt(variance / count);
  return out;
}

class Statistics {
 public:
  enum class Merge { sum, max };

  struct Counter {
    std::string name;
    double value = 0;
    Merge merge = Merge::sum;
  };

  // Adds `value` to the counter `name` (a Merge::max counter keeps the larger of the two).
  // A counter keeps the merge rule of its first addition.
  void add(std::string_view name, double value, Merge merge = Merge::sum);

  // Adds every counter of `other` under its own rule.
  void merge(const Statistics& other);

  // The value of counter `name`, or nullopt when it was never added.
  std::optional<double> find(std::string_view name) const noexcept;
  // Every counter, in the order of first addition.
  const std::vector<Counter>& counters() const noexcept { return counters_; }
  // Whether no counter was added.
  bool empty() const noexcept { return counters_.empty(); }

 private:
  std::vector<Counter> counters_;
};

}  // namespace ontime
