#pragma once
// Planner logs drawn from an instance's own distributions: the ground truth for checking that
// fitting (fitting.hpp) recovers what produced the data.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "ontime/model/planner_log.hpp"
#include "ontime/model/problem.hpp"

namespace ontime {

struct LogSamplingOptions {
  std::uint64_t attempts_per_action = 1000;
  std::uint64_t seed = 1;
  // Effort after which an attempt is cut off, in steps; 0 means the instance's deadline.
  Steps cutoff_steps = 0;
};

// For every action some skeleton uses (in the instance's order), `attempts_per_action`
// attempts: the planning time t and execution time x drawn from the action's distributions.
// An attempt with t <= cutoff is logged as found after a time drawn uniformly within its step,
// (t - 1 + v) step seconds with v in (0.001, 1] (so that rounding up gives back t exactly),
// with an execution time drawn the same way within step x (0 seconds when x = 0; (D + 1)
// steps when x is "never"). Any other attempt is logged as cut off after cutoff steps.
// Attempt i of action a draws from stream_seed(stream_seed(seed, a), i): same seed, same log.
std::vector<RefinementAttempt> sample_planner_log(const Problem& problem, const LogSamplingOptions& options);

// The same attempts, in the same order, handed to `emit` one at a time as they are drawn, so
// that a log of any length can be written without holding it (constant memory).
void sample_planner_log(const Problem& problem, const LogSamplingOptions& options,
                        const std::function<void(RefinementAttempt)>& emit);

// The same log written to `path` as JSON Lines (docs/formats.md), streamed in pieces of about
// 1 MiB, so a log of any length takes constant memory; written atomically (the old file stays
// until the whole log is there). Returns the records written. `ontime sample-log` and Python's
// ontime.sample_log call this.
std::uint64_t write_sampled_planner_log(const Problem& problem, const LogSamplingOptions& options,
                                        const std::filesystem::path& path);

}  // namespace ontime
