#include "ontime/util/error.hpp"

#include <utility>

namespace ontime {
namespace {

// The message with control bytes written `\u00XX`: it stays one line, and a NUL byte (from a
// key or an id of the input) does not end it where it is printed.
std::string printable(std::string text) {
  std::string shown;
  shown.reserve(text.size());
  for (const char c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      constexpr char kHex[] = "0123456789abcdef";
      shown += "\\u00";
      shown += kHex[(c >> 4) & 0xf];
      shown += kHex[c & 0xf];
    } else {
      shown += c;
    }
  }
  return shown;
}

}  // namespace

InputError::InputError(std::string source, std::string place, std::string rule)
    : std::runtime_error(printable(source + ": " + place + ": " + rule)),
      source_(std::move(source)),
      place_(std::move(place)),
      rule_(std::move(rule)) {}

UsageError unknown_name_error(std::string_view what, std::string_view name, std::span<const std::string> known) {
  std::string list;
  for (const std::string& candidate : known) list += (list.empty() ? "" : ", ") + candidate;
  return UsageError("unknown " + std::string(what) + " '" + std::string(name) + "' (known: " + list + ")");
}

}  // namespace ontime
