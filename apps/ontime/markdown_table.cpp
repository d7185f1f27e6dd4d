#include "markdown_table.hpp"

#include <algorithm>
#include <cstddef>

namespace ontime::cli {

std::string render_markdown(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& body) {
  std::vector<std::size_t> widths(header.size(), 0);
  const auto widen = [&widths](const std::vector<std::string>& line) {
    for (std::size_t i = 0; i < line.size(); ++i) {
      // Display width: count UTF-8 code points, not bytes (for "±" and "µ").
      std::size_t width = 0;
      for (const char c : line[i]) width += (static_cast<unsigned char>(c) & 0xC0) != 0x80 ? 1 : 0;
      widths[i] = std::max(widths[i], width);
    }
  };
  widen(header);
  for (const auto& line : body) widen(line);
  const auto render = [&widths](const std::vector<std::string>& line) {
    std::string out = "|";
    for (std::size_t i = 0; i < line.size(); ++i) {
      std::size_t width = 0;
      for (const char c : line[i]) width += (static_cast<unsigned char>(c) & 0xC0) != 0x80 ? 1 : 0;
      out += " " + line[i] + std::string(widths[i] - width, ' ') + " |";
    }
    return out + "\n";
  };
  std::string out = render(header);
  std::string rule = "|";
  for (const std::size_t width : widths) rule += std::string(width + 2, '-') + "|";
  out += rule + "\n";
  for (const auto& line : body) out += render(line);
  return out;
}

}  // namespace ontime::cli
