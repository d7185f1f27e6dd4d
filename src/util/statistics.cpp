#include "ontime/util/statistics.hpp"

#include <algorithm>

namespace ontime {

void Statistics::add(std::string_view name, double value, Merge merge) {
  for (Counter& counter : counters_) {
    if (counter.name != name) continue;
    counter.value = counter.merge == Merge::max ? std::max(counter.value, value) : counter.value + value;
    return;
  }
  counters_.push_back(Counter{std::string(name), value, merge});
}

void Statistics::merge(const Statistics& other) {
  for (const Counter& counter : other.counters_) add(counter.name, counter.value, counter.merge);
}

std::optional<double> Statistics::find(std::string_view name) const noexcept {
  for (const Counter& counter : counters_) {
    if (counter.name == name) return counter.value;
  }
  return std::nullopt;
}

}  // namespace ontime
