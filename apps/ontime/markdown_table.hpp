#pragma once
// Markdown tables for the commands' readable output, columns padded to their display width.

#include <string>
#include <vector>

namespace ontime::cli {

// A header row, the rule below it and the body rows; cells may hold UTF-8 ("±", "µ", "≤").
std::string render_markdown(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& body);

}  // namespace ontime::cli
