#pragma once
// Error types of the library. Callers (the CLI among them) map them to exit codes:
// InputError, UsageError and ResourceLimitError are the caller's to fix (exit 2),
// anything else is a defect of the library (exit 1).

#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace ontime {

// Bad input data. Names where it came from (`source`, usually a file path), the place
// inside it (a JSON path such as `actions.a3.planning.pmf."0"`, or `line 3, column 5`)
// and the rule that was broken.
class InputError : public std::runtime_error {
 public:
  // Message "source: place: rule" (control bytes written `\u00XX`, so that it stays one line).
  InputError(std::string source, std::string place, std::string rule);

  // Where the data came from, usually a file path.
  const std::string& source() const noexcept { return source_; }
  // The place inside it: a JSON path or a line and column.
  const std::string& place() const noexcept { return place_; }
  // The rule the data broke.
  const std::string& rule() const noexcept { return rule_; }

 private:
  std::string source_;
  std::string place_;
  std::string rule_;
};

// A request that cannot be served as asked: an unknown allocator name, an option out of
// range, an exact evaluation of an allocator whose choices are not a function of the state,
// an invalid problem or observation built in code, an output path that cannot be written.
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// The error for a name that is not one of `known`: "unknown WHAT 'NAME' (known: a, b, c)".
UsageError unknown_name_error(std::string_view what, std::string_view name, std::span<const std::string> known);

// A computation reached a cap the caller configured (states, memory) before finishing, or a
// file could not be written for want of disk space or quota. Raised instead of letting the
// process be killed for running out of memory.
class ResourceLimitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A computation ended early because its caller asked it to stop (a stop condition it was given
// returned true): an interrupted evaluation or solve. Nothing it would have written was written.
class Cancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace ontime
