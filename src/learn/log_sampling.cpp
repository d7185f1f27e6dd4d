#include "ontime/learn/log_sampling.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime {
namespace {

// Seconds within step `steps` (never on its lower edge): rounding up gives `steps` back.
template <class Generator>
double seconds_within_step(Steps steps, double step_seconds, Generator& generator) {
  if (steps == 0) return 0.0;
  const double within = 1.0 - 0.999 * uniform01(generator);
  return (static_cast<double>(steps - 1) + within) * step_seconds;
}

}  // namespace

std::vector<RefinementAttempt> sample_planner_log(const Problem& problem, const LogSamplingOptions& options) {
  std::vector<RefinementAttempt> log;
  sample_planner_log(problem, options, [&log](RefinementAttempt attempt) { log.push_back(std::move(attempt)); });
  return log;
}

void sample_planner_log(const Problem& problem, const LogSamplingOptions& options,
                        const std::function<void(RefinementAttempt)>& emit) {
  if (options.cutoff_steps < 0) throw UsageError("the cut-off must be >= 0 steps");
  const Steps cutoff = options.cutoff_steps > 0 ? options.cutoff_steps : problem.deadline();
  const double step = problem.step_seconds();
  // Every time written is at most `longest` steps: the log holds only finite seconds.
  Steps longest = std::max(cutoff, problem.deadline() + 1);
  for (const Action& action : problem.actions()) {
    longest = std::max({longest, static_cast<Steps>(action.planning.masses().size()),
                        static_cast<Steps>(action.execution.masses().size())});
  }
  if (!std::isfinite(static_cast<double>(longest) * step)) {
    throw UsageError(
        fmt::format("the times of this log (up to {} steps of {:g} seconds) are not finite numbers of seconds; "
                    "use a smaller step_seconds or cut-off",
                    longest, step));
  }
  for (int a = 0; a < problem.action_count(); ++a) {
    if (problem.position(a) < 0) continue;  // no skeleton uses it
    const Action& action = problem.action(a);
    const std::uint64_t action_seed = stream_seed(options.seed, static_cast<std::uint64_t>(a));
    for (std::uint64_t i = 0; i < options.attempts_per_action; ++i) {
      SplitMix64 generator(stream_seed(action_seed, i));
      RefinementAttempt attempt;
      attempt.action = action.id;
      attempt.trial = i;
      if (action.backtrack.never() < 1.0) {
        // Backtracking (SPEC §7): a motion or a backtrack, whichever ends the attempt first.
        const AttemptEnd end = draw_attempt_end(action, uniform01(generator));
        if (end.step != kNever && end.step <= cutoff) {
          attempt.planning_seconds = seconds_within_step(end.step, step, generator);
          if (end.found) {
            attempt.found = true;
            const Steps execution = action.execution.sample(generator);
            attempt.execution_seconds =
                seconds_within_step(execution == kNever ? problem.deadline() + 1 : execution, step, generator);
          } else {
            attempt.backtrack = problem.action(draw_culprit(problem, a, generator)).id;
          }
        } else {
          attempt.planning_seconds = static_cast<double>(cutoff) * step;
        }
        emit(std::move(attempt));
        continue;
      }
      const Steps planning = action.planning.sample(generator);
      const Steps execution = action.execution.sample(generator);
      if (planning != kNever && planning <= cutoff) {
        attempt.found = true;
        attempt.planning_seconds = seconds_within_step(planning, step, generator);
        const Steps execution_steps = execution == kNever ? problem.deadline() + 1 : execution;
        attempt.execution_seconds = seconds_within_step(execution_steps, step, generator);
      } else {
        attempt.planning_seconds = static_cast<double>(cutoff) * step;
      }
      emit(std::move(attempt));
    }
  }
}

std::uint64_t write_sampled_planner_log(const Problem& problem, const LogSamplingOptions& options,
                                        const std::filesystem::path& path) {
  AtomicFileWriter writer(path);
  std::string piece;
  std::uint64_t records = 0;
  sample_planner_log(problem, options, [&](const RefinementAttempt& attempt) {
    piece += planner_log_line(attempt);
    ++records;
    if (piece.size() >= (std::size_t{1} << 20)) {
      writer.write(piece);
      piece.clear();
    }
  });
  writer.write(piece);
  writer.commit();
  return records;
}

}  // namespace ontime
