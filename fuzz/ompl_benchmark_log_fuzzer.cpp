// Fuzzes the OMPL benchmark log reader: any input must either load or be rejected with
// InputError — never crash, hang, trip a sanitizer, or throw anything else. A loaded log must
// survive a write/read round trip unchanged (its cut-off runs are already at the time limit).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "ontime/model/ompl_benchmark_log.hpp"
#include "ontime/util/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const ontime::OmplBenchmarkRuns runs = ontime::parse_ompl_benchmark_log(text, "fuzz-input.log", {});
    ontime::OmplLogWriteOptions options;
    options.experiment = runs.experiment;
    options.time_limit_seconds = runs.time_limit_seconds;
    const std::string written = ontime::ompl_benchmark_log_text(runs.attempts, options);
    if (ontime::parse_ompl_benchmark_log(written, "round-trip.log", {}).attempts != runs.attempts) __builtin_trap();
  } catch (const ontime::InputError&) {
    // Rejected with a message: the expected outcome for bad input.
  }
  return 0;
}
