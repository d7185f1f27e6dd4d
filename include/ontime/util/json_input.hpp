#pragma once
// Support for readers of JSON input files, shared by the core and the domains library: JSON
// paths for error messages, strict parsing (duplicate keys are errors, not silently
// overwritten; files are read through read_input_file, ontime/input_file.hpp), every failure an InputError naming the
// file, the place and the rule. Not part of the allocation API (hence `detail`). The templates take the JSON type
// (nlohmann::json or nlohmann::ordered_json) as a parameter, so that this header needs nlohmann_json only where a
// reader includes <nlohmann/json.hpp> itself.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "ontime/util/error.hpp"
#include "ontime/util/input_file.hpp"

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
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
        // Shown escaped: a NUL would end the message where it is printed, a newline break it.
        constexpr char kHex[] = "0123456789abcdef";
        segment += "\\u00";
        segment += kHex[(c >> 4) & 0xf];
        segment += kHex[c & 0xf];
        continue;
      }
      segment += c;
    }
    segment += "\"";
  }
  return parent.empty() ? segment : parent + "." + segment;
}

// The deepest nesting of arrays and objects within each other that a file of OnTime's may have.
// Its formats need fewer than 10 levels (a boosted model's booster, the deepest, about 8); 256 is
// also the limit of the dicts and lists the Python package is given (python/ontime). The limit keeps every later walk
// of a document (a copy, a comparison, quoting a value in a message) within a bounded depth: nlohmann's parser does not
// recurse, but those walks do, and 300,000 nested '[' would exhaust the stack.
inline constexpr std::size_t kMaxJsonDepth = 256;

namespace json_quote {

// Recursive, but at most two levels deep: containers below the second are abbreviated.
template <class Json>
void append(std::string& out, const Json& value, std::size_t depth,  // NOLINT(misc-no-recursion)
            std::size_t limit) {
  if (out.size() > limit) return;
  if (!value.is_array() && !value.is_object()) {
    // A number, a boolean, null or a string: a string of a million characters is cut below.
    std::string text = value.dump(-1, ' ', false, Json::error_handler_t::replace);
    if (text.size() > limit) text.resize(limit + 1);  // beyond the limit: quote_json marks the cut
    out += text;
    return;
  }
  const bool array = value.is_array();
  if (value.empty()) {
    out += array ? "[]" : "{}";
    return;
  }
  // Two levels shown; deeper containers are abbreviated, so that quoting recurses at most twice.
  if (depth >= 2) {
    out += array ? "[...]" : "{...}";
    return;
  }
  out += array ? '[' : '{';
  bool first = true;
  for (auto item = value.begin(); item != value.end(); ++item) {
    if (!first) out += ", ";
    first = false;
    if (out.size() > limit) break;
    if (!array) out += Json(item.key()).dump(-1, ' ', false, Json::error_handler_t::replace) + ": ";
    append(out, item.value(), depth + 1, limit);
  }
  out += array ? ']' : '}';
}

}  // namespace json_quote

// `value` as JSON text for an error message ("got ..."), cut to about 80 characters ("..." marks
// the cut) and two levels of nesting: a message never grows with the input, and quoting never
// recurses more than twice.
template <class Json>
std::string quote_json(const Json& value) {
  constexpr std::size_t kLimit = 80;
  std::string out;
  json_quote::append(out, value, 0, kLimit);
  if (out.size() > kLimit) {
    out.resize(kLimit);
    out += "...";
  }
  return out;
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

// The value of a JSON number that is a whole number, written as an integer (`4`) or with a
// zero fraction part (`4.0`, as Python's json module writes floats), if it lies within
// [lowest, highest]; std::nullopt for anything else (not a number, a fraction, out of range).
template <class Json>
std::optional<std::int64_t> json_whole_number(const Json& value, std::int64_t lowest, std::int64_t highest) {
  if (value.is_number_unsigned()) {
    const auto number = value.template get<std::uint64_t>();
    if (highest < 0 || number > static_cast<std::uint64_t>(highest)) return std::nullopt;
    return static_cast<std::int64_t>(number) >= lowest ? std::optional<std::int64_t>(static_cast<std::int64_t>(number))
                                                       : std::nullopt;
  }
  if (value.is_number_integer()) {
    const auto number = value.template get<std::int64_t>();
    return number >= lowest && number <= highest ? std::optional<std::int64_t>(number) : std::nullopt;
  }
  if (!value.is_number_float()) return std::nullopt;
  const double number = value.template get<double>();
  // Compared as doubles: every int64 bound is within about 1e3 of a double, far below a step.
  if (!(std::trunc(number) == number && number >= static_cast<double>(lowest) &&
        number <= static_cast<double>(highest))) {
    return std::nullopt;
  }
  return static_cast<std::int64_t>(number);
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

// Line and column (1-based) of byte `offset` of `text`, as `line L, column C`.
inline std::string text_place(std::string_view text, std::size_t offset) {
  const std::string_view before = text.substr(0, std::min(offset, text.size()));
  const std::size_t line = 1 + static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n'));
  const std::size_t line_start = before.rfind('\n');
  const std::size_t column = before.size() - (line_start == std::string_view::npos ? 0 : line_start + 1) + 1;
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

// Builds the document of a strict parse (parse_json_strict) from nlohmann's SAX events in time
// linear in the text: members are appended without the container's own key search (linear
// per key for ordered_json), and duplicate keys are found with a hash set per open object.
template <class Json>
class StrictJsonBuilder {
 public:
  using number_integer_t = typename Json::number_integer_t;
  using number_unsigned_t = typename Json::number_unsigned_t;
  using number_float_t = typename Json::number_float_t;
  using string_t = typename Json::string_t;
  using binary_t = typename Json::binary_t;

  StrictJsonBuilder(std::string_view text, const std::string& source) : text_(text), source_(source) {}

  // Raised by a container that would be nested deeper than kMaxJsonDepth; parse_json_strict
  // finds its place in the text (the SAX events carry no position).
  struct TooDeep {};

  Json take() { return std::move(root_); }

  bool null() { return add(Json(nullptr)); }
  bool boolean(bool value) { return add(Json(value)); }
  bool number_integer(number_integer_t value) { return add(Json(value)); }
  bool number_unsigned(number_unsigned_t value) { return add(Json(value)); }
  bool number_float(number_float_t value, const string_t&) { return add(Json(value)); }
  bool string(string_t& value) { return add(Json(std::move(value))); }
  bool binary(binary_t& value) { return add(Json::binary(std::move(value))); }
  bool start_object(std::size_t) { return open(Json::object()); }
  bool start_array(std::size_t) { return open(Json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }

  bool key(string_t& key) {
    Frame& frame = frames_.back();
    if (!frame.keys.insert(key).second) {
      throw InputError(source_, json_member(path_of_open_containers(), key),
                       "duplicate key (each key may appear once in an object)");
    }
    frame.key = std::move(key);
    return true;
  }

  template <class Exception>
  bool parse_error(std::size_t position, const std::string& token, const Exception& error) {
    const std::string message = error.what();
    // nlohmann's message reads "[json.exception.parse_error.N] parse error at line L, column C: WHY".
    const std::size_t at = message.find("parse error at line ");
    const std::size_t colon = at == std::string::npos ? std::string::npos : message.find(": ", at);
    if (colon != std::string::npos) {
      const std::size_t place = at + std::string_view("parse error at ").size();
      throw InputError(source_, message.substr(place, colon - place), "invalid JSON: " + message.substr(colon + 2));
    }
    // A number too large for a double ("number overflow parsing '1e999'"): the position is the
    // end of the token.
    const std::size_t reason = message.find("] ");
    throw InputError(source_, text_place(text_, position - std::min(position, token.size())),
                     "invalid JSON: " + (reason == std::string::npos ? message : message.substr(reason + 2)));
  }

 private:
  struct Frame {
    Json* container;
    std::unordered_set<std::string> keys;  // of an object
    std::string key;                       // the member being read, of an object
  };

  // Places `value` in the innermost open container (or as the root) and returns where it is.
  Json* place(Json value) {
    if (frames_.empty()) {
      root_ = std::move(value);
      return &root_;
    }
    Frame& frame = frames_.back();
    if (frame.container->is_array()) {
      auto& array = *frame.container->template get_ptr<typename Json::array_t*>();
      array.push_back(std::move(value));
      return &array.back();
    }
    auto& object = *frame.container->template get_ptr<typename Json::object_t*>();
    if constexpr (requires { typename Json::object_t::Container; }) {
      // ordered_json: its emplace searches every key; `key` is known to be new.
      auto& members = static_cast<typename Json::object_t::Container&>(object);
      members.emplace_back(frame.key, std::move(value));
      return &members.back().second;
    } else {
      return &object.emplace(frame.key, std::move(value)).first->second;
    }
  }

  bool add(Json value) {
    place(std::move(value));
    return true;
  }

  bool open(Json container) {
    if (frames_.size() >= kMaxJsonDepth) throw TooDeep{};
    frames_.push_back(Frame{place(std::move(container)), {}, {}});
    return true;
  }

  bool close() {
    frames_.pop_back();
    return true;
  }

  // The JSON path of the innermost open container.
  std::string path_of_open_containers() const {
    std::string path;
    for (std::size_t i = 0; i + 1 < frames_.size(); ++i) {
      const Frame& frame = frames_[i];
      path =
          frame.container->is_object() ? json_member(path, frame.key) : json_index(path, frame.container->size() - 1);
    }
    return path;
  }

  std::string_view text_;
  const std::string& source_;
  Json root_;
  std::vector<Frame> frames_;
};

// The offset of the first '[' or '{' of `text` nested `depth` levels deep (counted from 0 at
// the top level), outside strings; text.size() if none. The text before it must be valid JSON
// so far (as the parser has found when it stops there): strings are then closed and escapes
// complete.
inline std::size_t deep_container_offset(std::string_view text, std::size_t depth) {
  std::size_t open = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (open == depth) return i;
      ++open;
    } else if ((c == ']' || c == '}') && open > 0) {
      --open;
    }
  }
  return text.size();
}

// Parses JSON text in time linear in its size; malformed text (a NUL byte among it) raises
// InputError at `line L, column C`, and a key that appears twice in one object raises
// InputError at its path.
template <class Json>
Json parse_json_strict(std::string_view text, const std::string& source) {
  // nlohmann reads a NUL byte as the end of the input: what follows would be ignored.
  if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos) {
    throw InputError(source, text_place(text, nul), "invalid JSON: a NUL byte (\\u0000) is not allowed in JSON text");
  }
  StrictJsonBuilder<Json> builder(text, source);
  try {
    Json::sax_parse(text.begin(), text.end(), &builder);  // JSON, strict: nothing may follow the value
  } catch (const typename StrictJsonBuilder<Json>::TooDeep&) {
    throw InputError(source, text_place(text, deep_container_offset(text, kMaxJsonDepth)),
                     "invalid JSON: arrays and objects nested more than " + std::to_string(kMaxJsonDepth) +
                         " levels deep (the limit of OnTime's files)");
  }
  return builder.take();
}

// Calls read(record, line) for each line of a JSON Lines text that is not blank, `line` counted
// from 1 over the whole text; each line is parsed strictly (parse_json_strict), and a malformed
// one raises InputError at `line L, column C` of the text (or `line L: PATH` for a key twice).
// Returns the number of records read.
template <class Json, class Read>
std::size_t for_each_json_line(std::string_view text, const std::string& source, Read&& read) {
  std::size_t records = 0;
  std::size_t line = 0;
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string_view::npos) end = text.size();
    ++line;
    const std::string_view content = text.substr(begin, end - begin);
    begin = end + 1;
    if (content.find_first_not_of(" \t\r") == std::string_view::npos) continue;  // blank
    const std::string place = "line " + std::to_string(line);
    Json record;
    try {
      record = parse_json_strict<Json>(content, source);
    } catch (const InputError& error) {
      // The parser counts lines within this one line (always its line 1); name the text's.
      constexpr std::string_view kFirstLine = "line 1, ";
      if (error.place().rfind(kFirstLine, 0) == 0) {
        throw InputError(source, place + ", " + error.place().substr(kFirstLine.size()), error.rule());
      }
      throw InputError(source, place + ": " + error.place(), error.rule());
    }
    read(record, line);
    ++records;
  }
  return records;
}

}  // namespace ontime::detail
