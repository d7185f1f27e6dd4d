#include "ontime/model/planner_log.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime {
namespace {

using Json = nlohmann::ordered_json;

class LineReader {
 public:
  LineReader(std::string source, std::size_t line) : source_(std::move(source)), line_(line) {}

  RefinementAttempt read(const Json& record) const {
    if (!record.is_object())
      fail("", "a record must be a JSON object (got " + detail::describe_json_type(record) + ")");
    for (const auto& [key, value] : record.items()) {
      if (key != "action" && key != "planning_seconds" && key != "found" && key != "execution_seconds" &&
          key != "trial" && key != "collision_checks" && key != "world" && key != "features" && key != "backtrack") {
        fail(key,
             "unknown key (expected 'action', 'planning_seconds', 'found', 'execution_seconds', 'trial', "
             "'collision_checks', 'world', 'features', 'backtrack')");
      }
    }
    RefinementAttempt attempt;
    const Json& action = required(record, "action");
    if (!action.is_string()) fail("action", "must be a string (got " + detail::describe_json_type(action) + ")");
    attempt.action = action.get<std::string>();
    if (attempt.action.empty()) fail("action", "must be a non-empty action id");
    attempt.planning_seconds = seconds(required(record, "planning_seconds"), "planning_seconds");
    const Json& found = required(record, "found");
    if (!found.is_boolean()) fail("found", "must be true or false (got " + detail::describe_json_type(found) + ")");
    attempt.found = found.get<bool>();
    if (attempt.found) {
      if (!record.contains("execution_seconds")) {
        fail("", "missing required key 'execution_seconds' (a found motion has an execution time)");
      }
      attempt.execution_seconds = seconds(record["execution_seconds"], "execution_seconds");
    } else if (record.contains("execution_seconds")) {
      fail("execution_seconds", "only a found motion has an execution time ('found' is false)");
    }
    if (record.contains("trial")) attempt.trial = count(record["trial"], "trial");
    if (record.contains("collision_checks"))
      attempt.collision_checks = count(record["collision_checks"], "collision_checks");
    if (record.contains("backtrack")) {
      const Json& blamed = record["backtrack"];
      if (!blamed.is_string() || blamed.get<std::string>().empty()) {
        fail("backtrack",
             "must be a non-empty string naming the earlier action blamed (got " + detail::quote_json(blamed) + ")");
      }
      if (attempt.found) fail("backtrack", "an attempt that backtracked found no motion ('found' must be false)");
      if (blamed.get<std::string>() == attempt.action) fail("backtrack", "an action cannot blame itself");
      attempt.backtrack = blamed.get<std::string>();
    }
    if (record.contains("world")) {
      const Json& world = record["world"];
      if (!world.is_string() || world.get<std::string>().empty()) {
        fail("world", "must be a non-empty string naming the world (got " + detail::quote_json(world) + ")");
      }
      attempt.world = world.get<std::string>();
    }
    if (record.contains("features")) {
      const Json& features = record["features"];
      if (!features.is_array() || features.empty()) {
        fail("features", "must be a non-empty array of numbers (got " + detail::describe_json_type(features) + ")");
      }
      attempt.features.reserve(features.size());
      for (std::size_t i = 0; i < features.size(); ++i) {
        const Json& value = features[i];
        if (!value.is_number() || !std::isfinite(value.get<double>())) {
          fail(detail::json_index("features", i), "must be a finite number (got " + detail::quote_json(value) + ")");
        }
        attempt.features.push_back(value.get<double>());
      }
    }
    return attempt;
  }

 private:
  std::string place() const { return "line " + std::to_string(line_); }

  [[noreturn]] void fail(const std::string& key, const std::string& rule) const {
    throw InputError(source_, key.empty() ? place() : place() + ": " + key, rule);
  }

  const Json& required(const Json& record, const char* key) const {
    if (!record.contains(key)) fail("", std::string("missing required key '") + key + "'");
    return record[key];
  }

  double seconds(const Json& value, const char* key) const {
    if (!value.is_number()) fail(key, "must be a number of seconds (got " + detail::describe_json_type(value) + ")");
    const double result = value.get<double>();
    if (!(std::isfinite(result) && result >= 0))
      fail(key, "must be a finite number of seconds >= 0 (got " + detail::quote_json(value) + ")");
    return result;
  }

  // A whole number >= 0, written as an integer or with a zero fraction part (`3.0`).
  std::uint64_t count(const Json& value, const char* key) const {
    if (value.is_number_unsigned()) return value.get<std::uint64_t>();
    const std::optional<std::int64_t> number =
        detail::json_whole_number(value, 0, std::numeric_limits<std::int64_t>::max());
    if (!number) fail(key, "must be a whole number >= 0 (got " + detail::quote_json(value) + ")");
    return static_cast<std::uint64_t>(*number);
  }

  std::string source_;
  std::size_t line_;
};

}  // namespace

std::vector<RefinementAttempt> parse_planner_log(std::string_view text, std::string_view source) {
  const std::string name(source);
  std::vector<RefinementAttempt> attempts;
  std::size_t feature_count = 0;
  detail::for_each_json_line<Json>(text, name, [&](const Json& record, std::size_t line) {
    attempts.push_back(LineReader(name, line).read(record));
    // Feature vectors are the same length throughout a log (one domain's extractor).
    const std::vector<double>& features = attempts.back().features;
    if (!features.empty()) {
      if (feature_count == 0) feature_count = features.size();
      if (features.size() != feature_count) {
        throw InputError(name, "line " + std::to_string(line) + ": features",
                         "has " + std::to_string(features.size()) + " numbers, but earlier records have " +
                             std::to_string(feature_count));
      }
    }
  });
  if (attempts.empty()) throw InputError(name, "file", "the log holds no records (one JSON object per line)");
  return attempts;
}

std::vector<RefinementAttempt> load_planner_log(const std::filesystem::path& path) {
  return parse_planner_log(read_input_file(path, "planner log"), path.string());
}

std::string planner_log_line(const RefinementAttempt& attempt) {
  Json record = Json::object();
  record["action"] = attempt.action;
  if (attempt.trial) record["trial"] = *attempt.trial;
  record["planning_seconds"] = attempt.planning_seconds;
  record["found"] = attempt.found;
  if (attempt.found) record["execution_seconds"] = attempt.execution_seconds;
  if (attempt.collision_checks) record["collision_checks"] = *attempt.collision_checks;
  if (attempt.backtrack) record["backtrack"] = *attempt.backtrack;
  if (attempt.world) record["world"] = *attempt.world;
  if (!attempt.features.empty()) record["features"] = attempt.features;
  return record.dump() + "\n";
}

void save_planner_log(std::span<const RefinementAttempt> attempts, const std::filesystem::path& path) {
  std::string text;
  for (const RefinementAttempt& attempt : attempts) text += planner_log_line(attempt);
  write_file_atomically(path, text);
}

}  // namespace ontime
