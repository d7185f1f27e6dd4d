#include "ontime/error.hpp"

#include <utility>

namespace ontime {

InputError::InputError(std::string source, std::string place, std::string rule)
    : std::runtime_error(source + ": " + place + ": " + rule),
      source_(std::move(source)),
      place_(std::move(place)),
      rule_(std::move(rule)) {}

}  // namespace ontime
