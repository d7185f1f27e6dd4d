#pragma once
// The report of a fit (`ontime fit`, `ontime collect`): what the log held about each action and
// the distributions learned from it, as a Markdown table or JSON.

#include <string>

#include "common.hpp"
#include "ontime/learn/fitting.hpp"

namespace ontime::cli {

std::string fit_report_markdown(const FitResult& fit);
Json fit_report_json(const FitResult& fit);

}  // namespace ontime::cli
