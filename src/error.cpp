#include "ontime/error.hpp"

#include <utility>

namespace ontime {

InputError::InputError(std::string source, std::string place, std::string rule)
    : std::runtime_error(source + ": " + place + ": " + rule),
      source_(std::move(source)),
      place_(std::move(place)),
      rule_(std::move(rule)) {}

UsageError unknown_name_error(std::string_view what, std::string_view name, std::span<const std::string> known) {
  std::string list;
  for (const std::string& candidate : known) list += (list.empty() ? "" : ", ") + candidate;
  return UsageError("unknown " + std::string(what) + " '" + std::string(name) + "' (known: " + list + ")");
}

}  // namespace ontime
