// Fuzzes the planner-log reader: any input must either load or be rejected with InputError —
// never crash, hang, trip a sanitizer, or throw anything else. A loaded log must survive a
// write/read round trip unchanged, and fitting it (one single-action skeleton per distinct
// action) must give a valid instance or an InputError.

#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>

#include "ontime/learn/fitting.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/model/skeleton_file.hpp"
#include "ontime/util/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const std::vector<ontime::RefinementAttempt> log = ontime::parse_planner_log(text, "fuzz-input.jsonl");
    std::string written;
    for (const ontime::RefinementAttempt& attempt : log) written += ontime::planner_log_line(attempt);
    if (ontime::parse_planner_log(written, "round-trip.jsonl") != log) __builtin_trap();

    std::set<std::string> actions;
    for (const ontime::RefinementAttempt& attempt : log) actions.insert(attempt.action);
    ontime::SkeletonList skeletons;
    skeletons.source = "fuzz-skeletons";
    for (const std::string& action : actions) {
      if (skeletons.skeletons.size() == 16) break;  // the most skeletons an instance holds
      skeletons.skeletons.push_back({action});
    }
    ontime::FitOptions options;
    options.step_seconds = 0.5;
    options.deadline = 20;
    options.laplace = 0.5;
    options.name = "fuzz";
    const ontime::FitResult fit = ontime::fit_problem(log, "fuzz-input.jsonl", skeletons, options);
    if (fit.problem.deadline() != 20) __builtin_trap();
  } catch (const ontime::InputError&) {
    // Rejected with a message: the expected outcome for bad input.
  }
  return 0;
}
