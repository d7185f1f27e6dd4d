#include "common.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "cluster_job.hpp"
#include "memory_limits.hpp"
#include "number_options.hpp"
#include "ontime/allocators/optimal.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/parallel.hpp"

namespace ontime::cli {

namespace {

std::string type_name(const Parameter& parameter) {
  switch (parameter.type) {
    case ParameterType::integer:
      return "INT";
    case ParameterType::real:
      return "REAL";
    case ParameterType::text:
      return "TEXT";
    case ParameterType::choice:
      return fmt::format("{{{}}}", fmt::join(parameter.choices, ","));
    case ParameterType::path:
      return "FILE";
  }
  return "VALUE";
}

}  // namespace

void AllocatorFlags::add_to(CLI::App& command) {
  const AllocatorRegistry& registry = allocator_registry();
  for (const Parameter& parameter : registry.parameters()) {
    std::string help =
        fmt::format("{}: {}", fmt::join(registry.kinds_with_parameter(parameter.name), ", "), parameter.help);
    if (!parameter.default_value.empty()) help += fmt::format(" (default {})", parameter.default_value);
    CLI::Option* option = command.add_option("--" + parameter.name, given[parameter.name], help);
    option->type_name(type_name(parameter));
    // Files may follow one flag (--policy a.json b.json); other values one per flag, repeatable.
    if (parameter.type != ParameterType::path)
      option->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  }
}

ParameterValues AllocatorFlags::values(std::size_t index, std::size_t instance_count) const {
  ParameterValues values;
  for (const auto& [name, list] : given) {
    if (list.empty()) continue;
    if (list.size() != 1 && list.size() != instance_count) {
      throw UsageError(fmt::format("--{}: give one value, or one per instance ({} given for {} instance{})", name,
                                   list.size(), instance_count, instance_count == 1 ? "" : "s"));
    }
    values.set(name, list[list.size() == 1 ? 0 : index]);
  }
  for (const Parameter& parameter : allocator_registry().parameters()) {
    const std::string* value = values.find(parameter.name);
    if (value == nullptr) continue;
    if (const std::optional<std::string> rule = parameter.violation(*value)) {
      throw UsageError("--" + parameter.name + ": " + *rule);
    }
  }
  return values;
}

std::size_t AllocatorFlags::max_states() const {
  // Only max-states: the other parameters may be given once per instance.
  ParameterValues values;
  const auto found = given.find("max-states");
  if (found != given.end() && !found->second.empty()) values.set("max-states", found->second.front());
  return max_states_of(values);
}

void MonteCarloFlags::add_to(CLI::App& command) {
  add_number_option(command, "--episodes", episodes, "Simulated episodes per evaluation", std::uint64_t{1});
  add_number_option(command, "--seed", seed, "Seed of the hidden worlds (episode i uses stream i of it)");
  add_threads_option(command, threads, "Worker threads (0: one per hardware thread); results do not depend on it");
}

MonteCarloOptions MonteCarloFlags::options() const {
  MonteCarloOptions options;
  options.episodes = episodes;
  options.seed = seed;
  options.threads = threads;
  options.ranks = job_ranks();
  return options;
}

void MonteCarloFlags::check_allocator_memory(const std::string& solver, const Problem& problem,
                                             const ParameterValues& values) const {
  cli::check_allocator_memory(solver, problem, values, episodes, threads);
}

void check_allocator_memory(const std::string& solver, const Problem& problem, const ParameterValues& values,
                            std::uint64_t episodes, unsigned threads) {
  allocator_registry().check_memory(solver, problem, values, worker_count(episodes, threads), flag_spelling());
}

CLI::Option* add_solver_option(CLI::App& command, std::string& solver) {
  return command
      .add_option("--solver", solver,
                  "Allocator: " + fmt::format("{}", fmt::join(allocator_registry().names(), ", ")) +
                      " ('ontime allocators' describes them)")
      ->required();
}

CLI::Option* add_act_option(CLI::App& command, std::string& act, const std::string& what) {
  return command
      .add_option("--act", act,
                  "plan-first (the robot executes a skeleton once it is refined in full; SPEC §2) or concurrent (it "
                  "executes refined actions while the rest is planned, and chooses when to start each; SPEC §10); "
                  "default: the instance's \"acting\", plan-first when it has none. " +
                      what)
      ->check(CLI::IsMember({"plan-first", "concurrent"}));
}

void check_solver_names(const std::vector<std::string>& names) {
  const std::vector<std::string> known = allocator_registry().names();
  if (names.empty()) throw UsageError("--solvers: give at least one allocator");
  for (auto name = names.begin(); name != names.end(); ++name) {
    if (name->empty()) {
      throw UsageError(fmt::format("--solvers: name {} is empty (a stray comma?)", name - names.begin() + 1));
    }
    if (std::find(known.begin(), known.end(), *name) == known.end()) throw unknown_name_error("solver", *name, known);
    if (std::find(names.begin(), name, *name) != name) {
      throw UsageError(fmt::format("--solvers: '{}' is given twice (one column per allocator)", *name));
    }
  }
}

void print_json(const Json& value) { fmt::print("{}\n", value.dump(2)); }

namespace {
bool quiet_progress = false;
}  // namespace

void set_quiet(bool quiet) noexcept { quiet_progress = quiet; }

double progress_line_seconds() {
  const char* text = std::getenv("ONTIME_PROGRESS_SECONDS");
  if (text == nullptr || *text == '\0') return 5.0;
  char* end = nullptr;
  const double seconds = std::strtod(text, &end);
  if (*end != '\0' || !(seconds >= 0) || seconds > 1e6) {
    throw UsageError(
        fmt::format("ONTIME_PROGRESS_SECONDS: must be a number of seconds from 0 to 1e6 (got '{}')", text));
  }
  return seconds;
}

std::string progress_duration(double seconds) {
  const auto whole = static_cast<std::uint64_t>(std::floor(std::max(0.0, seconds) + 0.5));
  if (whole >= 3600) return fmt::format("{}h{:02d}m", whole / 3600, whole % 3600 / 60);
  if (whole >= 60) return fmt::format("{}m{:02d}s", whole / 60, whole % 60);
  return fmt::format("{}s", whole);
}

// Only the rank that prints shows progress.
ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)),
      mode_(quiet_progress || !is_job_root() ? Mode::off
            : ::isatty(STDERR_FILENO) != 0   ? Mode::bar
                                             : Mode::lines),
      started_(std::chrono::steady_clock::now()),
      next_line_(started_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                std::chrono::duration<double>(mode_ == Mode::lines ? progress_line_seconds() : 0))) {}

ProgressBar::~ProgressBar() {
  if (mode_ == Mode::bar && last_percent_ >= 0) fmt::print(stderr, "\r\033[K");
}

bool ProgressBar::line_due() {
  const auto now = std::chrono::steady_clock::now();
  if (now < next_line_) return false;
  next_line_ = now + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                         std::chrono::duration<double>(progress_line_seconds()));
  return true;
}

void ProgressBar::status(std::string_view text) {
  if (mode_ == Mode::bar) {
    last_percent_ = 0;  // so that the destructor clears the line
    fmt::print(stderr, "\r{} {}\033[K", label_, text);
  } else if (mode_ == Mode::lines && line_due()) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    fmt::print(stderr, "ontime {}: {}, {} elapsed\n", label_, text, progress_duration(elapsed));
  } else {
    return;
  }
  std::fflush(stderr);
}

void ProgressBar::update(std::uint64_t done, std::uint64_t total) {
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  update(done, total,
         done == 0 ? std::nullopt
                   : std::optional<double>(elapsed * static_cast<double>(total - std::min(done, total)) /
                                           static_cast<double>(done)));
}

void ProgressBar::update(std::uint64_t done, std::uint64_t total, std::optional<double> seconds_left) {
  if (mode_ == Mode::off || total == 0) return;
  const int percent = static_cast<int>(100 * std::min(done, total) / total);
  if (mode_ == Mode::lines) {
    if (done == 0 || !line_due()) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    if (seconds_left) {
      fmt::print(stderr, "ontime {}: {}/{} ({}%), {} elapsed, about {} left\n", label_, done, total, percent,
                 progress_duration(elapsed), progress_duration(*seconds_left));
    } else {
      fmt::print(stderr, "ontime {}: {}/{} ({}%), {} elapsed\n", label_, done, total, percent,
                 progress_duration(elapsed));
    }
    std::fflush(stderr);
    return;
  }
  if (percent == last_percent_) return;
  last_percent_ = percent;
  constexpr int kWidth = 30;
  const int filled = percent * kWidth / 100;
  fmt::print(stderr, "\r{} [{}{}] {:3d}%", label_, std::string(static_cast<std::size_t>(filled), '#'),
             std::string(static_cast<std::size_t>(kWidth - filled), '.'), percent);
  std::fflush(stderr);
}

}  // namespace ontime::cli
