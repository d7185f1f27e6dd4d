#pragma once
// Numeric command-line options, read exactly. CLI11's own conversion saturates or wraps
// (`--seed -1` and `--seed 18446744073709551616` both became 2^64-1), reads a leading 0 as
// octal and accepts nan; here the whole text must be one decimal number of the option's type
// (std::from_chars) inside the option's inclusive range, or the command stops with a UsageError
// (exit 2) that names the option, the rule and the value as written.

#include <CLI/CLI.hpp>
#include <concepts>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

namespace ontime::cli {

// The most worker threads a command accepts: far above any machine this runs on, below the
// point where creating the threads fails for lack of resources.
inline constexpr unsigned kMaxThreads = 1024;

// The minimum of a real option that must be above zero (its messages say "> 0").
inline constexpr double kPositive = std::numeric_limits<double>::denorm_min();

// A number for messages: integers in full, reals in the shortest form that reads back
// (1e+308, never 309 digits).
std::string compact_number(double value);
std::string compact_number(std::int64_t value);
std::string compact_number(std::uint64_t value);

// `text` as a whole decimal number in [minimum, maximum]; UsageError naming `option` otherwise.
std::uint64_t parse_unsigned_option(std::string_view option, std::string_view text, std::uint64_t minimum,
                                    std::uint64_t maximum);
std::int64_t parse_signed_option(std::string_view option, std::string_view text, std::int64_t minimum,
                                 std::int64_t maximum);
// A finite real (no nan, no inf) in [minimum, maximum].
double parse_real_option(std::string_view option, std::string_view text, double minimum, double maximum);

// `text` as a T in [minimum, maximum], by the parser of T's kind.
template <class T>
T parse_number_option(std::string_view option, std::string_view text, T minimum, T maximum) {
  if constexpr (std::floating_point<T>) {
    return static_cast<T>(parse_real_option(option, text, minimum, maximum));
  } else if constexpr (std::unsigned_integral<T>) {
    return static_cast<T>(parse_unsigned_option(option, text, minimum, maximum));
  } else {
    return static_cast<T>(parse_signed_option(option, text, minimum, maximum));
  }
}

// Adds `name` (e.g. "--seed") storing into `value` the text read by parse_number_option; the
// help shows the current value of `value` as the default when `show_default`.
template <class T>
CLI::Option* add_number_option(CLI::App& command, const std::string& name, T& value, const std::string& help,
                               T minimum = std::numeric_limits<T>::lowest(), T maximum = std::numeric_limits<T>::max(),
                               bool show_default = true) {
  // The option's long name without dashes, for messages ("-o,--output" → "--output").
  const std::string shown = name.substr(name.rfind(',') == std::string::npos ? 0 : name.rfind(',') + 1);
  CLI::Option* option = command.add_option_function<std::string>(
      name,
      [&value, shown, minimum, maximum](const std::string& text) {
        value = parse_number_option<T>(shown, text, minimum, maximum);
      },
      help);
  option->type_name(std::floating_point<T> ? "REAL" : "INT");
  if (show_default) {
    if constexpr (std::floating_point<T>) {
      option->default_str(compact_number(static_cast<double>(value)));
    } else if constexpr (std::unsigned_integral<T>) {
      option->default_str(compact_number(static_cast<std::uint64_t>(value)));
    } else {
      option->default_str(compact_number(static_cast<std::int64_t>(value)));
    }
  }
  return option;
}

// `--threads`, 0 (one per hardware thread) to kMaxThreads.
CLI::Option* add_threads_option(CLI::App& command, unsigned& threads, const std::string& help);

}  // namespace ontime::cli
