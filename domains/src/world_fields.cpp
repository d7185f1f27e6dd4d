#include "world_fields.hpp"

#include <cstdio>

namespace ontime::domains::detail {

std::string number_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

}  // namespace ontime::domains::detail
