#include "ontime/solve/knapsack.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "ontime/mdp/state.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime {
namespace {

using Json = nlohmann::ordered_json;

std::int64_t positive_integer(const Json& value, const std::string& source, const std::string& path,
                              std::int64_t maximum) {
  // Whole numbers may be written with a zero fraction part (`4.0`).
  const std::optional<std::int64_t> whole = detail::json_whole_number(value, std::numeric_limits<std::int64_t>::min(),
                                                                      std::numeric_limits<std::int64_t>::max());
  if (!whole || *whole < 1)
    throw InputError(source, path, "must be a positive whole number (got " + detail::quote_json(value) + ")");
  const std::int64_t number = *whole;
  if (number > maximum) {
    throw InputError(source, path,
                     "must be at most " + std::to_string(maximum) + " (got " + detail::quote_json(value) + ")");
  }
  return number;
}

}  // namespace

Knapsack parse_knapsack(std::string_view text, std::string_view source_view) {
  const std::string source(source_view);
  const Json root = detail::parse_json_strict<Json>(text, source);
  if (!root.is_object()) throw InputError(source, "top level", "a knapsack must be a JSON object");
  for (const auto& [key, value] : root.items()) {
    if (key != "capacity" && key != "items") {
      throw InputError(source, detail::json_member("", key), "unknown key (expected 'capacity', 'items')");
    }
  }
  if (!root.contains("capacity")) throw InputError(source, "top level", "missing required key 'capacity'");
  if (!root.contains("items")) throw InputError(source, "top level", "missing required key 'items'");
  Knapsack knapsack;
  // The capacity becomes the deadline of the reduced instance.
  knapsack.capacity = positive_integer(root["capacity"], source, "capacity", Problem::kMaxDeadline);
  const Json& items = root["items"];
  if (!items.is_array() || items.empty()) throw InputError(source, "items", "must be a non-empty array of items");
  // The reduction exists to be solved exactly, so its items are bounded by the exact solver.
  if (items.size() > static_cast<std::size_t>(kMaxExactSkeletons)) {
    throw InputError(source, "items",
                     "at most " + std::to_string(kMaxExactSkeletons) + " items (one skeleton each; got " +
                         std::to_string(items.size()) + ")");
  }
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string path = detail::json_index("items", i);
    const Json& item = items[i];
    if (!item.is_object()) throw InputError(source, path, "an item must be an object {\"weight\": w, \"value\": v}");
    for (const auto& [key, value] : item.items()) {
      if (key != "weight" && key != "value") {
        throw InputError(source, detail::json_member(path, key), "unknown key (expected 'weight', 'value')");
      }
    }
    for (const char* required : {"weight", "value"}) {
      if (!item.contains(required))
        throw InputError(source, path, std::string("missing required key '") + required + "'");
    }
    knapsack.items.push_back(
        {positive_integer(item["weight"], source, detail::json_member(path, "weight"), Distribution::kMaxStep - 1),
         positive_integer(item["value"], source, detail::json_member(path, "value"), std::int64_t{1} << 20)});
  }
  return knapsack;
}

Knapsack load_knapsack(const std::filesystem::path& path) {
  return parse_knapsack(read_input_file(path, "knapsack"), path.string());
}

double reduction_epsilon(const Knapsack& knapsack) {
  std::int64_t largest = 0;
  for (const KnapsackItem& item : knapsack.items) largest = std::max(largest, item.value);
  const auto h = static_cast<double>(largest);
  const auto m = static_cast<double>(knapsack.items.size());
  return 1.0 / (h * h * m * m * m);
}

Problem reduce_knapsack(const Knapsack& knapsack, std::string name) {
  const double epsilon = reduction_epsilon(knapsack);
  const auto deadline = static_cast<Steps>(knapsack.capacity);
  std::vector<Action> actions;
  std::vector<std::vector<int>> skeletons;
  for (std::size_t k = 0; k < knapsack.items.size(); ++k) {
    const KnapsackItem& item = knapsack.items[k];
    // CDF 0 before w, eps v from w to W, 1 after W: mass eps v at w and the rest at W + 1 (past
    // the deadline). An item heavier than W never finishes in time: all its mass past W.
    const auto last = static_cast<std::size_t>(std::max<std::int64_t>(item.weight, knapsack.capacity + 1));
    std::vector<double> planning(last + 1, 0.0);
    const double early = epsilon * static_cast<double>(item.value);
    planning[static_cast<std::size_t>(item.weight)] += early;
    planning[static_cast<std::size_t>(knapsack.capacity) + 1] += 1.0 - early;
    std::string id = "item";
    id += std::to_string(k + 1);
    actions.emplace_back(std::move(id), Distribution::from_pmf(std::move(planning)), Distribution::from_pmf({1.0}));
    skeletons.push_back({static_cast<int>(k)});
  }
  return Problem(std::move(name), deadline, 1.0, std::move(actions), std::move(skeletons),
                 "Knapsack reduction of Theorem 1: capacity " + std::to_string(knapsack.capacity) + ", " +
                     std::to_string(knapsack.items.size()) + " items, eps = 1/(H^2 K^3)");
}

double schedule_success(const Knapsack& knapsack, const std::vector<std::uint8_t>& chosen) {
  const double epsilon = reduction_epsilon(knapsack);
  double failure = 1.0;
  for (std::size_t k = 0; k < knapsack.items.size(); ++k) {
    if (chosen[k] != 0) failure *= 1.0 - epsilon * static_cast<double>(knapsack.items[k].value);
  }
  return 1.0 - failure;
}

}  // namespace ontime
