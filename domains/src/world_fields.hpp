#pragma once
// Internal: typed access to the members of a domain's world file, each failure an InputError
// naming the file, the JSON path and the rule. Shared by the world readers of every domain.

#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/domains/world_types.hpp"
#include "ontime/model/distribution.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime::domains::detail {

using Json = nlohmann::ordered_json;
using ontime::read_input_file;
using ontime::detail::describe_json_type;
using ontime::detail::json_index;
using ontime::detail::json_member;
using ontime::detail::parse_json_strict;

// "%g" of a number, for messages.
std::string number_text(double value);

class WorldFields {
 public:
  explicit WorldFields(std::string source) : source_(std::move(source)) {}

  const std::string& source() const noexcept { return source_; }

  [[noreturn]] void fail(const std::string& place, const std::string& rule) const {
    throw InputError(source_, place, rule);
  }

  void check_keys(const Json& object, const std::string& path, std::initializer_list<std::string_view> allowed) const {
    ontime::detail::check_known_keys(object, path, allowed, source_);
  }

  const Json& member(const Json& object, const std::string& path, const char* key) const {
    if (!object.contains(key))
      fail(path.empty() ? "top level" : path, std::string("missing required key '") + key + "'");
    return object[key];
  }

  const Json& object_at(const Json& value, const std::string& path) const {
    if (!value.is_object()) fail(path, "must be an object (got " + describe_json_type(value) + ")");
    return value;
  }

  std::string string_at(const Json& value, const std::string& path) const {
    if (!value.is_string()) fail(path, "must be a string (got " + describe_json_type(value) + ")");
    return value.get<std::string>();
  }

  double finite(const Json& value, const std::string& path) const {
    if (!value.is_number()) fail(path, "must be a number (got " + describe_json_type(value) + ")");
    const double result = value.get<double>();
    if (!std::isfinite(result)) fail(path, "must be a finite number");
    return result;
  }

  double positive(const Json& value, const std::string& path) const {
    const double result = finite(value, path);
    if (!(result > 0)) fail(path, "must be a positive number (got " + ontime::detail::quote_json(value) + ")");
    return result;
  }

  std::vector<double> numbers(const Json& value, const std::string& path, std::size_t count, const char* what) const {
    if (!value.is_array() || value.size() != count) {
      fail(path, std::string("must be an array of ") + std::to_string(count) + " numbers (" + what + ")");
    }
    std::vector<double> result;
    for (std::size_t i = 0; i < count; ++i) result.push_back(finite(value[i], json_index(path, i)));
    return result;
  }

  // The `collection` member: deadline (whole steps), step_seconds, checks_per_second.
  CollectionDefaults collection(const Json& value) const {
    object_at(value, "collection");
    check_keys(value, "collection", {"deadline", "step_seconds", "checks_per_second"});
    CollectionDefaults collection;
    const Json& deadline = member(value, "collection", "deadline");
    const std::optional<std::int64_t> steps = ontime::detail::json_whole_number(deadline, 1, Problem::kMaxDeadline);
    if (!steps) {
      fail("collection.deadline",
           "must be a whole number of steps between 1 and " + std::to_string(Problem::kMaxDeadline));
    }
    collection.deadline = static_cast<Steps>(*steps);
    collection.step_seconds = positive(member(value, "collection", "step_seconds"), "collection.step_seconds");
    collection.checks_per_second =
        positive(member(value, "collection", "checks_per_second"), "collection.checks_per_second");
    return collection;
  }

 private:
  std::string source_;
};

}  // namespace ontime::domains::detail
