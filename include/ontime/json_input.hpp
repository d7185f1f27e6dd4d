#pragma once
// Support for readers of JSON input files, shared by the core and the domains library: JSON
// paths for error messages, strict parsing (duplicate keys are errors, not silently
// overwritten; files are read through read_input_file, ontime/input_file.hpp), every failure an InputError naming the
// file, the place and the rule. Not part of the allocation API (hence `detail`). The templates take the JSON type
// (nlohmann::json or nlohmann::ordered_json) as a parameter, so that this header needs nlohmann_json only where a
// reader includes <nlohmann/json.hpp> itself.

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/error.hpp"
#include "ontime/input_file.hpp"

namespace ontime::detail {

// `parent.key`, or `parent."key"` when the key is not an identifier (e.g. `pmf."0"`).
inline std::string json_member(const std::string& parent, std::string_view key) {
  bool identifier = !key.empty() && (std::isalpha(static_cast<unsigned char>(key[0])) || key[0] == '_');
  for (const char c : key) identifier = identifier && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
  std::string segment;
  if (identifier) {
    segment = std::string(key);
  } else {
    segment = "\"";
    for (const char c : key) {
      if (c == '"' || c == '\\') segment += '\\';
      segment += c;
    }
    segment += "\"";
  }
  return parent.empty() ? segment : parent + "." + segment;
}

// "null", "a boolean", "a number", "a string", "an array" or "an object", for messages.
template <class Json>
std::string describe_json_type(const Json& value) {
  if (value.is_null()) return "null";
  if (value.is_boolean()) return "a boolean";
  if (value.is_number()) return "a number";
  if (value.is_string()) return "a string";
  if (value.is_array()) return "an array";
  return "an object";
}

inline std::string json_index(const std::string& parent, std::size_t index) {
  return parent + "[" + std::to_string(index) + "]";
}

// Raises InputError at the first key of `object` (at `path`) that is not in `allowed`.
template <class Json>
void check_known_keys(const Json& object, const std::string& path, std::initializer_list<std::string_view> allowed,
                      const std::string& source) {
  for (const auto& [key, value] : object.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
    std::string expected;
    for (const std::string_view name : allowed) expected += (expected.empty() ? "'" : ", '") + std::string(name) + "'";
    throw InputError(source, json_member(path, key), "unknown key (expected " + expected + ")");
  }
}

// Parses JSON text; malformed text raises InputError at `line L, column C`, and a key that
// appears twice in one object raises InputError at its path.
template <class Json>
Json parse_json_strict(std::string_view text, const std::string& source) {
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;
    std::size_t index;
    bool started;
  };
  std::vector<Frame> frames;
  const auto path_of_parents = [&frames] {
    std::string path;
    for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
      path = frames[i].object ? json_member(path, frames[i].key) : json_index(path, frames[i].index);
    }
    return path;
  };
  const auto enter_element = [&frames] {
    if (!frames.empty() && !frames.back().object) {
      Frame& parent = frames.back();
      parent.index = parent.started ? parent.index + 1 : 0;
      parent.started = true;
    }
  };
  const auto callback = [&](int, typename Json::parse_event_t event, Json& parsed) -> bool {
    using Event = typename Json::parse_event_t;
    switch (event) {
      case Event::object_start:
        enter_element();
        frames.push_back(Frame{true, {}, {}, 0, false});
        break;
      case Event::array_start:
        enter_element();
        frames.push_back(Frame{false, {}, {}, 0, false});
        break;
      case Event::key: {
        Frame& frame = frames.back();
        std::string key = parsed.template get<std::string>();
        if (!frame.keys.insert(key).second) {
          std::string path = path_of_parents();
          throw InputError(source, json_member(path, key), "duplicate key (each key may appear once in an object)");
        }
        frame.key = std::move(key);
        break;
      }
      case Event::object_end:
      case Event::array_end:
        frames.pop_back();
        break;
      case Event::value:
        enter_element();
        break;
    }
    return true;
  };
  try {
    return Json::parse(text.begin(), text.end(), callback, true, false);
  } catch (const typename Json::parse_error& error) {
    // nlohmann's message reads "[json.exception.parse_error.N] parse error at line L, column C: WHY".
    const std::string message = error.what();
    const std::size_t at = message.find("parse error at line ");
    const std::size_t colon = at == std::string::npos ? std::string::npos : message.find(": ", at);
    if (colon != std::string::npos) {
      const std::size_t place = at + std::string_view("parse error at ").size();
      throw InputError(source, message.substr(place, colon - place), "invalid JSON: " + message.substr(colon + 2));
    }
    throw InputError(source, "byte " + std::to_string(error.byte), "invalid JSON: " + message);
  } catch (const typename Json::out_of_range& error) {
    // A number too large for a double ("number overflow parsing '1e999'"): nlohmann gives no
    // position, so the place is that of the first occurrence of the quoted token.
    const std::string message = error.what();
    const std::size_t open = message.find('\'');
    const std::size_t close = open == std::string::npos ? std::string::npos : message.rfind('\'');
    std::string place = "number";
    if (open != std::string::npos && close > open + 1) {
      const std::size_t at = text.find(std::string_view(message).substr(open + 1, close - open - 1));
      if (at != std::string_view::npos) {
        const std::string_view before = text.substr(0, at);
        const std::size_t line = 1 + static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n'));
        const std::size_t line_start = before.rfind('\n');
        const std::size_t column = at - (line_start == std::string_view::npos ? 0 : line_start + 1) + 1;
        place = "line " + std::to_string(line) + ", column " + std::to_string(column);
      }
    }
    const std::size_t reason = message.find("] ");
    throw InputError(source, place,
                     "invalid JSON: " + (reason == std::string::npos ? message : message.substr(reason + 2)));
  }
}

}  // namespace ontime::detail
