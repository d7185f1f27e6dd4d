#pragma once
// Named counters that an allocator or a world reports about its own work (search iterations,
// tree sizes, refinements started, ...), so that the episode runner, the CLI's JSON output
// and the Python bindings can report any component's figures without knowing its kind.
//
// Each counter says how two values merge: summed (work done, over episodes and threads) or
// the larger kept (peaks). Counters keep the order in which they were first added, so a
// report lists them the same way every time.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace ontime {

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

  std::optional<double> find(std::string_view name) const noexcept;
  const std::vector<Counter>& counters() const noexcept { return counters_; }
  bool empty() const noexcept { return counters_.empty(); }

 private:
  std::vector<Counter> counters_;
};

}  // namespace ontime
