#include "ontime/model/exogenous_chain.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <unordered_set>

#include "model/chain_fields.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/input_file.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime {
namespace {

using ChainJson = nlohmann::ordered_json;

constexpr std::string_view kFormat = "ontime-chain";
constexpr int kVersion = 1;

void require_valid(const ExogenousChain& chain) {
  if (const std::optional<ChainFault> fault = find_chain_fault(chain)) {
    throw UsageError("chain '" + chain.name + "': " + fault->place + ": " + fault->rule);
  }
}

}  // namespace

int ExogenousChain::state_index(std::string_view state) const noexcept {
  for (std::size_t i = 0; i < states.size(); ++i) {
    if (states[i] == state) return static_cast<int>(i);
  }
  return -1;
}

std::optional<ChainFault> find_chain_fault(const ExogenousChain& chain) {
  const std::size_t n = chain.states.size();
  if (n == 0) return ChainFault{"states", "a chain has at least one state"};
  if (n > static_cast<std::size_t>(kMaxChainStates)) {
    return ChainFault{"states",
                      "at most " + std::to_string(kMaxChainStates) + " states (got " + std::to_string(n) + ")"};
  }
  std::unordered_set<std::string_view> seen;
  for (std::size_t i = 0; i < n; ++i) {
    if (chain.states[i].empty()) return ChainFault{detail::json_index("states", i), "a state's name is not empty"};
    if (!seen.insert(chain.states[i]).second) {
      return ChainFault{detail::json_index("states", i), "state '" + chain.states[i] + "' is named twice"};
    }
  }
  if (chain.start < 0 || static_cast<std::size_t>(chain.start) >= n) {
    return ChainFault{"start", "must be one of the chain's states"};
  }
  if (chain.transitions.size() != n) {
    return ChainFault{"transitions", "must have one row per state (" + std::to_string(n) + " rows, got " +
                                         std::to_string(chain.transitions.size()) + ")"};
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::vector<double>& row = chain.transitions[i];
    const std::string place = detail::json_index("transitions", i);
    if (row.size() != n) {
      return ChainFault{
          place, "must have one entry per state (" + std::to_string(n) + ", got " + std::to_string(row.size()) + ")"};
    }
    double sum = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      if (!(std::isfinite(row[j]) && row[j] >= 0.0)) {
        return ChainFault{detail::json_index(place, j), "a transition probability is a finite number >= 0"};
      }
      sum += row[j];
    }
    if (!(std::abs(sum - 1.0) <= kChainRowTolerance)) {
      return ChainFault{place, "the probabilities of leaving state '" + chain.states[i] + "' sum to 1 (got " +
                                   ChainJson(sum).dump() + ")"};
    }
  }
  return std::nullopt;
}

namespace detail {

ExogenousChain read_chain_fields(const nlohmann::ordered_json& object, const std::string& path, std::string name,
                                 const std::string& source) {
  const auto fail = [&source](const std::string& place, const std::string& rule) {
    throw InputError(source, place, rule);
  };
  const auto at = [&path](std::string_view key) { return json_member(path, key); };
  for (const char* key : {"states", "start", "transitions"}) {
    if (!object.contains(key))
      fail(path.empty() ? "top level" : path, std::string("missing required key '") + key + "'");
  }
  ExogenousChain chain;
  chain.name = std::move(name);
  const ChainJson& states = object["states"];
  if (!states.is_array())
    fail(at("states"), "must be an array of state names (got " + describe_json_type(states) + ")");
  for (std::size_t i = 0; i < states.size(); ++i) {
    if (!states[i].is_string()) {
      fail(json_index(at("states"), i), "a state's name is a string (got " + detail::quote_json(states[i]) + ")");
    }
    chain.states.push_back(states[i].get<std::string>());
  }
  const ChainJson& start = object["start"];
  if (!start.is_string()) fail(at("start"), "must be a state's name (got " + detail::quote_json(start) + ")");
  chain.start = chain.state_index(start.get<std::string>());
  if (chain.start < 0) fail(at("start"), "'" + start.get<std::string>() + "' is not one of the chain's states");
  const ChainJson& rows = object["transitions"];
  if (!rows.is_array()) fail(at("transitions"), "must be an array of rows (got " + describe_json_type(rows) + ")");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string place = json_index(at("transitions"), i);
    if (!rows[i].is_array()) fail(place, "a row is an array of numbers (got " + describe_json_type(rows[i]) + ")");
    std::vector<double> row;
    for (std::size_t j = 0; j < rows[i].size(); ++j) {
      if (!rows[i][j].is_number()) {
        fail(json_index(place, j), "a transition probability is a number (got " + detail::quote_json(rows[i][j]) + ")");
      }
      row.push_back(rows[i][j].get<double>());
    }
    chain.transitions.push_back(std::move(row));
  }
  if (const std::optional<ChainFault> fault = find_chain_fault(chain)) {
    fail(path.empty() ? fault->place : path + "." + fault->place, fault->rule);
  }
  return chain;
}

}  // namespace detail

ExogenousChain parse_chain(std::string_view text, std::string_view source) {
  const std::string name(source);
  const auto root = detail::parse_json_strict<ChainJson>(text, name);
  const auto fail = [&name](const std::string& place, const std::string& rule) { throw InputError(name, place, rule); };
  if (!root.is_object())
    fail("top level", "a chain file is a JSON object (got " + detail::describe_json_type(root) + ")");
  detail::check_known_keys(root, "", {"format", "version", "name", "states", "start", "transitions"}, name);
  if (!root.contains("format") || root["format"] != std::string(kFormat)) {
    fail("format", "not a chain file (expected \"" + std::string(kFormat) + "\")");
  }
  if (!root.contains("version") || !root["version"].is_number_integer() || root["version"].get<int>() != kVersion) {
    fail("version", "this OnTime reads version " + std::to_string(kVersion) + " of the chain format (got " +
                        (root.contains("version") ? detail::quote_json(root["version"]) : "none") + ")");
  }
  for (const char* key : {"name", "states", "start", "transitions"}) {
    if (!root.contains(key)) fail("top level", std::string("missing required key '") + key + "'");
  }
  if (!root["name"].is_string() || root["name"].get<std::string>().empty()) {
    fail("name", "must be a non-empty string (got " + detail::quote_json(root["name"]) + ")");
  }
  return detail::read_chain_fields(root, "", root["name"].get<std::string>(), name);
}

ExogenousChain load_chain(const std::filesystem::path& path) {
  return parse_chain(read_input_file(path, "chain file"), path.string());
}

std::string chain_to_json(const ExogenousChain& chain) {
  require_valid(chain);
  if (chain.name.empty()) throw UsageError("a chain has a non-empty name");
  ChainJson root = ChainJson::object();
  root["format"] = std::string(kFormat);
  root["version"] = kVersion;
  root["name"] = chain.name;
  root["states"] = chain.states;
  root["start"] = chain.states[static_cast<std::size_t>(chain.start)];
  // One row per line: a matrix that reads as one.
  std::string text = root.dump(2);
  text.erase(text.size() - 2);  // the closing "\n}"
  text += ",\n  \"transitions\": [";
  for (std::size_t i = 0; i < chain.transitions.size(); ++i) {
    text += (i == 0 ? "\n    " : ",\n    ") + ChainJson(chain.transitions[i]).dump();
  }
  text += "\n  ]\n}\n";
  return text;
}

void save_chain(const ExogenousChain& chain, const std::filesystem::path& path) {
  write_file_atomically(path, chain_to_json(chain));
}

std::vector<double> chain_distribution(const ExogenousChain& chain, int from, std::int64_t steps,
                                       const std::function<bool()>& stop) {
  require_valid(chain);
  const std::size_t n = chain.states.size();
  if (from < 0 || static_cast<std::size_t>(from) >= n) {
    throw UsageError("chain '" + chain.name + "': state " + std::to_string(from) + " is not one of its " +
                     std::to_string(n) + " states");
  }
  if (steps < 0)
    throw UsageError("chain '" + chain.name + "': a number of steps >= 0 (got " + std::to_string(steps) + ")");
  std::vector<double> now(n, 0.0);
  std::vector<double> next(n);
  now[static_cast<std::size_t>(from)] = 1.0;
  for (std::int64_t t = 0; t < steps; ++t) {
    if (t % 4096 == 0 && stop && stop())
      throw Cancelled("the chain's distribution was stopped at step " + std::to_string(t));
    advance_chain_distribution(chain, now, next);
    now.swap(next);
  }
  return now;
}

void advance_chain_distribution(const ExogenousChain& chain, std::span<const double> now, std::span<double> next) {
  // (By hand: one fixed summation order, so the same bits on every machine, and the rows of
  // states the chain cannot be in skipped.)
  std::fill(next.begin(), next.end(), 0.0);
  for (std::size_t i = 0; i < now.size(); ++i) {
    if (now[i] == 0.0) continue;
    const std::vector<double>& row = chain.transitions[i];
    for (std::size_t j = 0; j < next.size(); ++j) next[j] += now[i] * row[j];
  }
}

}  // namespace ontime
