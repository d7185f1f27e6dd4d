#include "ontime/model/ompl_benchmark_log.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <system_error>

#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/input_file.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime {
namespace {

using Json = nlohmann::ordered_json;

// The run properties the reader uses; every other one is skipped.
constexpr std::string_view kTime = "time REAL";
constexpr std::string_view kSolved = "solved BOOLEAN";
constexpr std::string_view kLength = "solution length REAL";
constexpr std::string_view kTrial = "trial INTEGER";
constexpr std::string_view kChecks = "collision checks INTEGER";

// A line's content for a message: control characters escaped (a NUL would cut the message, a
// line break split it), long lines shortened.
std::string shown(std::string_view text) {
  constexpr std::size_t kLongest = 60;
  std::string out = "'";
  for (std::size_t i = 0; i < text.size() && i < kLongest; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f) {
      out += fmt::format("\\x{:02x}", c);
    } else {
      out += static_cast<char>(c);
    }
  }
  if (text.size() > kLongest) out += "...";
  return out + "'";
}

bool starts_with(std::string_view text, std::string_view prefix) { return text.substr(0, prefix.size()) == prefix; }
bool ends_with(std::string_view text, std::string_view suffix) {
  return text.size() >= suffix.size() && text.substr(text.size() - suffix.size()) == suffix;
}

std::string_view trim(std::string_view text) {
  const std::size_t begin = text.find_first_not_of(" \t");
  if (begin == std::string_view::npos) return {};
  return text.substr(begin, text.find_last_not_of(" \t") - begin + 1);
}

std::optional<double> parse_real(std::string_view text) {
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

std::optional<std::uint64_t> parse_count(std::string_view text) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

// The lines of a log, one at a time, with their numbers. A line ends at '\n'; carriage returns
// before it (files written on Windows) are not part of it.
class Lines {
 public:
  Lines(std::string_view text, std::string source) : text_(text), source_(std::move(source)) {}

  const std::string& source() const { return source_; }
  std::size_t number() const { return number_; }
  bool at_end() const { return position_ >= text_.size(); }

  // The next line; at the end of the file, an InputError saying what was expected.
  std::string_view next(std::string_view expected) {
    if (at_end()) throw InputError(source_, "end of file", "the file ends where " + std::string(expected) + " belongs");
    std::size_t end = text_.find('\n', position_);
    if (end == std::string_view::npos) end = text_.size();
    std::string_view line = text_.substr(position_, end - position_);
    position_ = end + 1;
    ++number_;
    while (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return line;
  }

  // The next line without taking it (std::nullopt at the end of the file).
  std::optional<std::string_view> peek() const {
    if (at_end()) return std::nullopt;
    Lines copy = *this;
    return copy.next("");
  }

  std::string place() const { return "line " + std::to_string(number_); }

  [[noreturn]] void fail(const std::string& rule) const { throw InputError(source_, place(), rule); }
  [[noreturn]] void fail(std::string_view property, const std::string& rule) const {
    throw InputError(source_, place() + ": " + std::string(property), rule);
  }

  // A line `PREFIX REST`; returns REST.
  std::string_view after(std::string_view prefix, std::string_view what) {
    const std::string_view line = next(what);
    if (!starts_with(line, prefix)) {
      fail("expected " + std::string(what) + " ('" + std::string(prefix) + "...'), got " + shown(line));
    }
    return line.substr(prefix.size());
  }

  // A line `N SUFFIX`; returns N (a whole number >= 0).
  std::uint64_t count(std::string_view suffix, std::string_view what) {
    const std::string_view line = next(what);
    if (!ends_with(line, suffix))
      fail("expected " + std::string(what) + " ('N" + std::string(suffix) + "'), got " + shown(line));
    const std::optional<std::uint64_t> value = parse_count(line.substr(0, line.size() - suffix.size()));
    if (!value) fail("expected " + std::string(what) + ": N must be a whole number >= 0, got " + shown(line));
    return *value;
  }

  // A line `X SUFFIX`; returns X (a number).
  double real(std::string_view suffix, std::string_view what) {
    const std::string_view line = next(what);
    if (!ends_with(line, suffix))
      fail("expected " + std::string(what) + " ('X" + std::string(suffix) + "'), got " + shown(line));
    const std::optional<double> value = parse_real(line.substr(0, line.size() - suffix.size()));
    if (!value) fail("expected " + std::string(what) + ": X must be a number, got " + shown(line));
    return *value;
  }

  // A block `<<<|`, lines, `|>>>` (OMPL's multi-line strings). When `optional` and the next line
  // does not open a block, nothing is taken.
  void block(std::string_view what, bool optional) {
    if (optional) {
      const std::optional<std::string_view> line = peek();
      if (!line || !starts_with(*line, "<<<|")) return;
    }
    if (!starts_with(next(what), "<<<|")) fail("expected " + std::string(what) + " (a block opened by '<<<|')");
    const std::size_t opened = number_;
    while (true) {
      if (at_end()) {
        throw InputError(source_, "line " + std::to_string(opened),
                         "the block of " + std::string(what) + " opened here is never closed by '|>>>'");
      }
      // OMPL writes the text and then '|>>>': when the text has no final line break, the
      // closing mark ends its last line.
      const std::string_view line = next(what);
      if (starts_with(line, "|>>>") || ends_with(line, "|>>>")) return;
    }
  }

 private:
  std::string_view text_;
  std::string source_;
  std::size_t position_ = 0;
  std::size_t number_ = 0;
};

// The index of each property the reader uses in a planner's run lines.
struct Columns {
  std::optional<std::size_t> time, solved, length, trial, checks;
};

class Reader {
 public:
  Reader(std::string_view text, std::string source, const OmplLogReadOptions& options)
      : lines_(text, std::move(source)), options_(options) {}

  OmplBenchmarkRuns read() {
    OmplBenchmarkRuns runs;
    read_preamble(runs);
    const std::uint64_t planners = lines_.count(" planners", "the number of planners");
    for (std::uint64_t p = 0; p < planners; ++p) read_planner(runs);
    while (!lines_.at_end()) {
      const std::string_view line = lines_.next("");
      if (!trim(line).empty()) {
        lines_.fail("text after the last of the " + std::to_string(planners) +
                    " planners the log announces: " + shown(line));
      }
    }
    if (runs.attempts.empty()) throw InputError(lines_.source(), "file", "the log holds no runs");
    return runs;
  }

 private:
  void read_preamble(OmplBenchmarkRuns& runs) {
    // An optional first line `LIBRARY version VERSION`.
    std::string_view line = lines_.next("the experiment's name");
    if (!starts_with(line, "Experiment ")) {
      // OMPL writes `OMPL version VERSION`; some builds leave VERSION empty.
      if (line.find(" version") == std::string_view::npos) {
        lines_.fail("expected 'Experiment NAME' (or 'LIBRARY version VERSION' before it), got " + shown(line));
      }
      line = lines_.next("the experiment's name");
      if (!starts_with(line, "Experiment ")) lines_.fail("expected 'Experiment NAME', got " + shown(line));
    }
    runs.experiment = std::string(line.substr(std::string_view("Experiment ").size()));
    if (runs.experiment.empty()) lines_.fail("the experiment's name is empty");

    // Optional experiment properties, `NAME TYPE = VALUE` each.
    if (const auto next = lines_.peek(); next && ends_with(*next, " experiment properties")) {
      const std::uint64_t count = lines_.count(" experiment properties", "the number of experiment properties");
      for (std::uint64_t i = 0; i < count; ++i) {
        if (lines_.next("an experiment property").find(" = ") == std::string_view::npos) {
          lines_.fail("an experiment property must read 'NAME TYPE = VALUE' (" + std::to_string(count) +
                      " are announced)");
        }
      }
    }
    lines_.after("Running on ", "the host name");
    lines_.after("Starting at ", "the start date");
    lines_.block("the setup", false);
    lines_.block("the CPU information", true);
    const std::string_view seed = lines_.next("the random seed");
    if (!ends_with(seed, " is the random seed") ||
        !parse_count(seed.substr(0, seed.size() - std::string_view(" is the random seed").size()))) {
      lines_.fail("expected 'N is the random seed' (N a whole number >= 0), got " + shown(seed));
    }
    runs.time_limit_seconds = lines_.real(" seconds per run", "the time limit");
    if (!(std::isfinite(runs.time_limit_seconds) && runs.time_limit_seconds > 0)) {
      lines_.fail("the time limit must be a finite number of seconds > 0 (got " +
                  fmt::format("{}", runs.time_limit_seconds) + ")");
    }
    lines_.real(" MB per run", "the memory limit");
    if (const auto next = lines_.peek(); next && ends_with(*next, " runs per planner")) {
      // OMPL writes 0 when the runs of a planner shared one time budget: each run was then
      // limited by what the earlier ones left, which the log does not say.
      if (lines_.count(" runs per planner", "the number of runs per planner") == 0) {
        lines_.fail(
            "0 runs per planner: the runs shared one time budget, so a run's own time limit is not known (run the "
            "benchmark with a run count)");
      }
    }
    lines_.real(" seconds spent to collect the data", "the total time");
    if (const auto next = lines_.peek(); next && (ends_with(*next, " enum type") || ends_with(*next, " enum types"))) {
      const std::string_view enums = lines_.next("the number of enum types");
      const std::string_view number = enums.substr(0, enums.find(' '));
      const std::optional<std::uint64_t> count = parse_count(number);
      if (!count) lines_.fail("expected 'N enum type' (N a whole number >= 0), got " + shown(enums));
      for (std::uint64_t i = 0; i < *count; ++i) {
        if (lines_.next("an enum type").find('|') == std::string_view::npos) {
          lines_.fail("an enum type must read 'NAME|VALUE|...' (" + std::to_string(*count) + " are announced)");
        }
      }
    }
  }

  void read_planner(OmplBenchmarkRuns& runs) {
    const std::string planner(lines_.next("a planner's name"));
    const std::size_t planner_line = lines_.number();
    if (trim(planner).empty()) lines_.fail("a planner's name must not be empty");
    const std::string action = action_of(runs.experiment, planner, planner_line);

    const std::uint64_t common = lines_.count(" common properties", "the number of the planner's common properties");
    for (std::uint64_t i = 0; i < common; ++i) {
      if (lines_.next("a common property").find(" = ") == std::string_view::npos) {
        lines_.fail("a common property must read 'NAME = VALUE' (" + std::to_string(common) + " are announced)");
      }
    }

    const std::uint64_t property_count =
        lines_.count(" properties for each run", "the number of properties for each run");
    const std::size_t properties_line = lines_.number();
    std::vector<std::string> properties;
    Columns columns;
    for (std::uint64_t i = 0; i < property_count; ++i) {
      const std::string_view property = lines_.next("a run property");
      const std::size_t space = property.rfind(' ');
      if (space == std::string_view::npos || space == 0 || space + 1 == property.size()) {
        lines_.fail("a run property must read 'NAME TYPE', got " + shown(property));
      }
      for (const std::string& seen : properties) {
        if (seen == property) lines_.fail("the run property " + shown(property) + " is listed twice");
      }
      const std::size_t index = properties.size();
      if (property == kTime) columns.time = index;
      if (property == kSolved) columns.solved = index;
      if (property == kLength) columns.length = index;
      if (property == kTrial) columns.trial = index;
      if (property == kChecks) columns.checks = index;
      properties.emplace_back(property);
    }
    for (const auto& [column, property] : {std::pair{columns.time, kTime}, std::pair{columns.solved, kSolved}}) {
      if (!column) {
        throw InputError(lines_.source(), "line " + std::to_string(properties_line),
                         "the planner's runs have no property '" + std::string(property) + "'");
      }
    }

    const std::uint64_t run_count = lines_.count(" runs", "the number of runs");
    for (std::uint64_t r = 0; r < run_count; ++r) {
      runs.attempts.push_back(read_run(lines_.next("a run's values"), properties, columns, action, runs));
    }

    // Optional progress data, then the closing '.'.
    std::string_view line = lines_.next("the '.' that ends a planner's data");
    if (ends_with(line, " progress properties for each run")) {
      const std::string_view number = line.substr(0, line.find(' '));
      const std::optional<std::uint64_t> count = parse_count(number);
      if (!count) lines_.fail("expected 'N progress properties for each run', got " + shown(line));
      for (std::uint64_t i = 0; i < *count; ++i) lines_.next("a progress property");
      const std::uint64_t progress_runs = lines_.count(" runs", "the number of runs with progress data");
      for (std::uint64_t i = 0; i < progress_runs; ++i) lines_.next("a run's progress data");
      line = lines_.next("the '.' that ends a planner's data");
    }
    if (trim(line) != ".") {
      lines_.fail("expected '.' after the " + std::to_string(run_count) + " runs of planner " + shown(planner) +
                  ", got " + shown(line));
    }
  }

  std::string action_of(const std::string& experiment, const std::string& planner, std::size_t line) const {
    if (!options_.action.empty()) return options_.action;
    if (options_.mapping == nullptr) return planner;
    for (const OmplActionRule& rule : options_.mapping->rules) {
      if (rule.experiment && *rule.experiment != experiment) continue;
      if (rule.planner && *rule.planner != planner) continue;
      return rule.action;
    }
    throw InputError(lines_.source(), "line " + std::to_string(line),
                     "no rule of the mapping " + options_.mapping->source + " matches experiment " + shown(experiment) +
                         ", planner " + shown(planner));
  }

  RefinementAttempt read_run(std::string_view line, const std::vector<std::string>& properties, const Columns& columns,
                             const std::string& action, const OmplBenchmarkRuns& runs) const {
    // Each value is followed by ';' (OMPL writes "; "), an empty value meaning "not recorded".
    std::vector<std::string_view> values;
    std::size_t begin = 0;
    while (true) {
      const std::size_t end = line.find(';', begin);
      if (end == std::string_view::npos) {
        if (!trim(line.substr(begin)).empty()) {
          lines_.fail("a run's values must each end with ';' (text after the last: " + shown(line.substr(begin)) + ")");
        }
        break;
      }
      values.push_back(trim(line.substr(begin, end - begin)));
      begin = end + 1;
    }
    if (values.size() != properties.size()) {
      lines_.fail("a run has " + std::to_string(values.size()) + " values, the planner announces " +
                  std::to_string(properties.size()) + " properties for each run");
    }
    RefinementAttempt attempt;
    attempt.action = action;

    const std::string_view time_text = values[*columns.time];
    const std::optional<double> time = parse_real(time_text);
    if (!time) lines_.fail(kTime, "must be a number of seconds, got " + shown(time_text));
    if (!(std::isfinite(*time) && *time >= 0)) {
      lines_.fail(kTime, "must be a finite number of seconds >= 0, got " + shown(time_text));
    }
    const std::string_view solved_text = values[*columns.solved];
    bool solved = false;
    if (solved_text == "1" || solved_text == "true") {
      solved = true;
    } else if (solved_text != "0" && solved_text != "false") {
      lines_.fail(kSolved, "must be 0 or 1, got " + shown(solved_text));
    }

    // Found within the limit: its time and its motion. Anything else: cut off at the limit.
    attempt.found = solved && *time <= runs.time_limit_seconds;
    attempt.planning_seconds = attempt.found ? *time : runs.time_limit_seconds;
    if (attempt.found) {
      if (!columns.length) {
        lines_.fail("a solved run needs a solution length, and the planner's runs have no property '" +
                    std::string(kLength) + "'");
      }
      const std::string_view length_text = values[*columns.length];
      const std::optional<double> length = parse_real(length_text);
      if (!length || !(std::isfinite(*length) && *length >= 0)) {
        lines_.fail(kLength, "a solved run's solution length must be a finite number >= 0, got " + shown(length_text));
      }
      attempt.execution_seconds = *length / options_.speed;
      if (!std::isfinite(attempt.execution_seconds)) {
        lines_.fail(kLength, "the solution length over the speed is not a finite number of seconds");
      }
    }
    attempt.trial = count_value(values, columns.trial, kTrial);
    attempt.collision_checks = count_value(values, columns.checks, kChecks);
    return attempt;
  }

  std::optional<std::uint64_t> count_value(const std::vector<std::string_view>& values,
                                           const std::optional<std::size_t>& column, std::string_view property) const {
    if (!column || values[*column].empty()) return std::nullopt;
    const std::optional<std::uint64_t> value = parse_count(values[*column]);
    if (!value) lines_.fail(property, "must be a whole number >= 0, got " + shown(values[*column]));
    return value;
  }

  Lines lines_;
  const OmplLogReadOptions& options_;
};

void check_line(std::string_view text, std::string_view what) {
  if (trim(text).empty()) throw UsageError(std::string(what) + " must not be empty or blank");
  if (text.find('\n') != std::string_view::npos || text.back() == '\r') {
    throw UsageError(std::string(what) + " " + shown(text) +
                     " cannot be one line of an OMPL benchmark log (it holds a line break)");
  }
}

std::string number(double value) { return fmt::format("{}", value); }

}  // namespace

OmplActionMapping parse_ompl_action_mapping(std::string_view text, std::string_view source) {
  const std::string name(source);
  const Json root = detail::parse_json_strict<Json>(text, name);
  if (!root.is_object()) {
    throw InputError(name, "top level",
                     "must be a JSON object with a 'rules' member (got " + detail::describe_json_type(root) + ")");
  }
  detail::check_known_keys(root, "", {"rules"}, name);
  if (!root.contains("rules")) throw InputError(name, "top level", "missing required key 'rules'");
  const Json& rules = root["rules"];
  if (!rules.is_array()) {
    throw InputError(name, "rules", "must be an array of rules (got " + detail::describe_json_type(rules) + ")");
  }
  if (rules.empty()) throw InputError(name, "rules", "must hold at least one rule");
  OmplActionMapping mapping;
  mapping.source = name;
  for (std::size_t i = 0; i < rules.size(); ++i) {
    const std::string path = detail::json_index("rules", i);
    const Json& entry = rules[i];
    if (!entry.is_object()) {
      throw InputError(name, path, "a rule must be a JSON object (got " + detail::describe_json_type(entry) + ")");
    }
    detail::check_known_keys(entry, path, {"experiment", "planner", "action"}, name);
    OmplActionRule rule;
    const auto text_member = [&](const char* key) -> std::optional<std::string> {
      if (!entry.contains(key)) return std::nullopt;
      const Json& value = entry[key];
      const std::string place = detail::json_member(path, key);
      if (!value.is_string()) {
        throw InputError(name, place, "must be a string (got " + detail::describe_json_type(value) + ")");
      }
      if (value.get<std::string>().empty()) throw InputError(name, place, "must not be empty");
      return value.get<std::string>();
    };
    rule.experiment = text_member("experiment");
    rule.planner = text_member("planner");
    const std::optional<std::string> action = text_member("action");
    if (!action) throw InputError(name, path, "missing required key 'action'");
    rule.action = *action;
    if (!rule.experiment && !rule.planner) {
      throw InputError(name, path, "a rule must name an 'experiment', a 'planner' or both");
    }
    mapping.rules.push_back(std::move(rule));
  }
  return mapping;
}

OmplActionMapping load_ompl_action_mapping(const std::filesystem::path& path) {
  return parse_ompl_action_mapping(read_input_file(path, "action mapping"), path.string());
}

OmplBenchmarkRuns parse_ompl_benchmark_log(std::string_view text, std::string_view source,
                                           const OmplLogReadOptions& options) {
  if (!(std::isfinite(options.speed) && options.speed > 0)) {
    throw UsageError("the speed must be a finite number > 0 (got " + number(options.speed) + ")");
  }
  return Reader(text, std::string(source), options).read();
}

OmplBenchmarkRuns load_ompl_benchmark_log(const std::filesystem::path& path, const OmplLogReadOptions& options) {
  return parse_ompl_benchmark_log(read_input_file(path, "OMPL benchmark log"), path.string(), options);
}

std::string ompl_benchmark_log_text(std::span<const RefinementAttempt> attempts, const OmplLogWriteOptions& options) {
  check_line(options.experiment, "the experiment's name");
  if (!(std::isfinite(options.time_limit_seconds) && options.time_limit_seconds > 0)) {
    throw UsageError("the time limit must be a finite number of seconds > 0 (got " +
                     number(options.time_limit_seconds) + ")");
  }
  // One planner per action, in order of first appearance; its runs in the order given.
  std::vector<std::string> actions;
  std::map<std::string, std::vector<const RefinementAttempt*>> runs_of;
  bool trials = false;
  bool checks = false;
  double total_seconds = 0;
  for (const RefinementAttempt& attempt : attempts) {
    check_line(attempt.action, "the action id");
    auto [entry, fresh] = runs_of.try_emplace(attempt.action);
    if (fresh) actions.push_back(attempt.action);
    entry->second.push_back(&attempt);
    trials = trials || attempt.trial.has_value();
    checks = checks || attempt.collision_checks.has_value();
    total_seconds += attempt.planning_seconds;
  }
  // The properties in OMPL's order (sorted by name); the optional ones only when some run has them.
  std::vector<std::string_view> properties;
  if (checks) properties.push_back(kChecks);
  properties.push_back(kLength);
  properties.push_back(kSolved);
  properties.push_back(kTime);
  if (trials) properties.push_back(kTrial);

  // The setup block ends at the first line holding '|>>>'.
  if (options.setup.find("|>>>") != std::string::npos) throw UsageError("the setup text must not hold '|>>>'");
  std::string setup = options.setup;
  if (!setup.empty() && setup.back() != '\n') setup += '\n';
  std::string out;
  out += "Experiment " + options.experiment + "\n";
  out += "0 experiment properties\n";
  out += "Running on UNKNOWN\n";
  out += "Starting at UNKNOWN\n";
  out += "<<<|\n" + setup + "|>>>\n";
  out += std::to_string(options.seed) + " is the random seed\n";
  out += number(options.time_limit_seconds) + " seconds per run\n";
  out += "0 MB per run\n";
  std::set<std::size_t> counts;
  for (const auto& [action, runs] : runs_of) counts.insert(runs.size());
  if (counts.size() == 1) out += std::to_string(*counts.begin()) + " runs per planner\n";
  out += number(total_seconds) + " seconds spent to collect the data\n";
  out += std::to_string(actions.size()) + " planners\n";
  for (const std::string& action : actions) {
    const std::vector<const RefinementAttempt*>& runs = runs_of.at(action);
    out += action + "\n0 common properties\n";
    out += std::to_string(properties.size()) + " properties for each run\n";
    for (const std::string_view property : properties) out += std::string(property) + "\n";
    out += std::to_string(runs.size()) + " runs\n";
    for (const RefinementAttempt* run : runs) {
      if (checks) out += (run->collision_checks ? std::to_string(*run->collision_checks) : "") + "; ";
      out += (run->found ? number(run->execution_seconds) : "") + "; ";
      out += std::string(run->found ? "1" : "0") + "; ";
      out += number(run->planning_seconds) + "; ";
      if (trials) out += (run->trial ? std::to_string(*run->trial) : "") + "; ";
      out += "\n";
    }
    out += ".\n";
  }
  return out;
}

void save_ompl_benchmark_log(std::span<const RefinementAttempt> attempts, const std::filesystem::path& path,
                             const OmplLogWriteOptions& options) {
  write_file_atomically(path, ompl_benchmark_log_text(attempts, options));
}

}  // namespace ontime
