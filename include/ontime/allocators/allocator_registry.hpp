#pragma once
// Allocator kinds that describe themselves, in one registry.
//
// Each allocator's own source file declares its kind: a name, a one-line summary, its
// capabilities, its parameters (name, type, default, allowed range or values, help) and how to
// make a factory of allocators for an Mdp from parameter values. Everything that offers a choice
// of allocators (the command line, its `--help` and JSON output, the studies, the tests, the
// Python bindings) reads the registry, so a new allocator or a new parameter needs no change
// outside its own files (docs/architecture.md: "Adding an allocator").
//
// Parameter values are given as text by name (as a command line or keyword arguments give
// them); the registry parses and checks them against the declaration, and a kind reads them,
// defaults filled in, through `ParameterReader`. Several kinds may declare a parameter of the
// same name (dp-rerun's aggregation is also used by mcts's dp-rerun rollouts): they must declare
// it alike, so that one value means one thing.

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/allocators/decision_budget.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/util/memory.hpp"

namespace ontime {

// What a kind of allocator can do or needs.
enum class Capability : std::uint32_t {
  stationary = 1U << 0,    // the choice is a function of the state: exact evaluation applies
  randomised = 1U << 1,    // draws random numbers (seeded per episode)
  anytime = 1U << 2,       // uses the budget passed with each decision
  needs_policy = 1U << 3,  // needs a trained policy (a file), not just the instance
  optimal = 1U << 4,       // attains the optimum: the reference column, not a competitor
  certified = 1U << 5,     // each decision carries a certified bound on its loss (a yardstick, like optimal)
  chains = 1U << 6,        // takes instances with exogenous chains or expiry (SPEC §9)
};

class Capabilities {
 public:
  constexpr Capabilities() noexcept = default;
  // The set of the capabilities listed.
  constexpr Capabilities(std::initializer_list<Capability> list) noexcept {
    for (const Capability capability : list) bits_ |= static_cast<std::uint32_t>(capability);
  }
  // Whether `capability` is in the set.
  constexpr bool has(Capability capability) const noexcept {
    return (bits_ & static_cast<std::uint32_t>(capability)) != 0;
  }
  // The names of the capabilities held, in declaration order ("stationary", "randomised", ...).
  std::vector<std::string> names() const;

 private:
  std::uint32_t bits_ = 0;
};

// The capability's name: "stationary", "needs-policy", ... (as Capabilities::names spells it).
std::string_view to_string(Capability capability) noexcept;

enum class ParameterType { integer, real, text, choice, path };
// The type's name: "integer", "real", "text", "choice" or "path".
std::string_view to_string(ParameterType type) noexcept;

struct Parameter {
  // Declarations of each type (every field set, so that kinds read as a list of these).
  static Parameter integer(std::string name, std::uint64_t default_value, double minimum, double maximum,
                           std::string help);
  static Parameter real(std::string name, double default_value, double minimum, double maximum, std::string help);
  static Parameter choice(std::string name, std::string default_value, std::vector<std::string> choices,
                          std::string help);
  static Parameter text(std::string name, std::string default_value, std::string help);
  // A file; no default (the kind says what its absence means).
  static Parameter path(std::string name, std::string help);

  std::string name;  // lower case with hyphens: "max-states"
  ParameterType type = ParameterType::real;
  std::string default_value;  // text form; empty: no default (the kind says what that means)
  double minimum = -std::numeric_limits<double>::infinity();  // integer and real
  double maximum = std::numeric_limits<double>::infinity();
  std::vector<std::string> choices;  // ParameterType::choice
  std::string help;
  static constexpr double kNoLimit = std::numeric_limits<double>::infinity();

  // The values allowed, in words: ">= 1", "in [0, 1]", "one of sum, max, self"; empty for
  // free text.
  std::string allowed() const;

  // The rule `value` breaks ("must be a whole number >= 1 (got '0')"), or nothing when it is of
  // the parameter's type, range and choices.
  std::optional<std::string> violation(std::string_view value) const;
  // Throws UsageError "parameter 'NAME': RULE" for a value that breaks a rule.
  void check(std::string_view value) const;
};

// Parameter values given by name, as text. Values for parameters a kind does not declare are
// ignored by that kind (one set of values can serve several kinds, as in a table).
class ParameterValues {
 public:
  ParameterValues() = default;
  // The values given as {name, value} pairs.
  ParameterValues(std::initializer_list<std::pair<const std::string, std::string>> values) : values_(values) {}
  // Sets (or replaces) the value of parameter `name`.
  void set(std::string name, std::string value) { values_[std::move(name)] = std::move(value); }
  // The value given for `name`, or null when none was.
  const std::string* find(std::string_view name) const;
  // Every value given, by name.
  const std::map<std::string, std::string, std::less<>>& all() const noexcept { return values_; }

 private:
  std::map<std::string, std::string, std::less<>> values_;
};

struct AllocatorKind;

// A kind's view of the values: checked, defaults filled in.
class ParameterReader {
 public:
  // Reads `values` as `kind` declares its parameters; both must outlive the reader.
  ParameterReader(const AllocatorKind& kind, const ParameterValues& values) : kind_(&kind), values_(&values) {}
  // Whether the value was given (not defaulted).
  bool given(std::string_view name) const;
  double real(std::string_view name) const;
  std::uint64_t integer(std::string_view name) const;
  std::string text(std::string_view name) const;  // text, choice and path parameters
  const ParameterValues& values() const noexcept { return *values_; }

 private:
  const Parameter& declared(std::string_view name) const;
  std::string raw(std::string_view name) const;
  const AllocatorKind* kind_;
  const ParameterValues* values_;
};

// A counter an allocator reports in collect_statistics.
struct CounterDeclaration {
  std::string name;  // "iterations"
  std::string help;  // what it counts
};

// The counters that the tools read by meaning: an allocator that searches at each decision
// reports the searches it ran and their iterations (the modelled clock charges the iterations,
// studies report iterations per search).
inline constexpr const char* kSearchesCounter = "searches";
inline constexpr const char* kIterationsCounter = "iterations";

// The memory one kind of allocator may hold, beyond the instance's own tables.
struct MemoryNeed {
  std::string parameter = {};  // the whole-number parameter that caps it: "max-tree-mib", "max-states"
  // The bytes it may hold at most for `problem` under the given values.
  std::function<double(const Problem& problem, const ParameterReader& parameters)> bytes = {};
  // Held by each allocator (one per thread: a search tree), or once by the factory and shared
  // by every allocator it makes (the exact solver's table).
  bool per_allocator = true;
};

// What running a kind needs beyond the instance.
struct AllocatorNeeds {
  // The budget of each decision that the given values ask for (an anytime kind's iterations or
  // seconds); an unset budget when they ask for none, so that the caller's default applies (a
  // live session gives a share of a slice). Null: the kind takes no budget.
  std::function<DecisionBudget(const ParameterReader& parameters)> decision_budget = {};
  // Null `bytes`: the kind holds nothing that grows with its parameters.
  MemoryNeed memory = {};
  std::vector<CounterDeclaration> counters = {};
};

struct AllocatorKind {
  std::string name;     // "dp-rerun"
  std::string summary;  // one line
  Capabilities capabilities;
  std::vector<Parameter> parameters;
  // A factory of independent allocators for `mdp` (which must outlive it). Precomputation is
  // done here, once, and shared by the allocators it makes. Throws UsageError for values that
  // cannot serve (e.g. a policy trained for another instance), ResourceLimitError at a cap.
  std::function<AllocatorFactory(const Mdp& mdp, const ParameterReader& parameters)> make;
  AllocatorNeeds needs = {};
  // Acting while planning (SPEC §10): the commit rule in a line (when the robot starts an action,
  // dropping the skeletons not through it); empty when the kind decides plan-first only.
  std::string commit_rule = {};
  // A factory of allocators for a ConcurrentMdp (which must outlive it). Null with a commit rule:
  // the eager rule (EagerCommitAllocator) around the allocators `make` makes for its plan-first Mdp.
  std::function<ConcurrentAllocatorFactory(const ConcurrentMdp& mdp, const ParameterReader& parameters)>
      make_concurrent = {};

  // Whether the kind acts while planning (has a commit rule).
  bool acts_while_planning() const noexcept { return !commit_rule.empty(); }
  // Whether the kind lists `counter` among the counters it reports (needs.counters).
  bool declares_counter(std::string_view counter) const;
};

class AllocatorRegistry {
 public:
  // Kinds in registration order: the order of the paper's tables, optimal first.
  const std::vector<AllocatorKind>& kinds() const noexcept { return kinds_; }
  std::vector<std::string> names() const;
  // Names of the kinds that have every capability in `with` and none in `without`.
  std::vector<std::string> names(Capabilities with, Capabilities without = {}) const;

  // Throws UsageError "unknown allocator 'x' (known: ...)".
  const AllocatorKind& find(std::string_view name) const;

  // Every parameter declared by some kind, once, in order of first declaration.
  std::vector<Parameter> parameters() const;
  // The kinds that declare `name`.
  std::vector<std::string> kinds_with_parameter(std::string_view name) const;

  // Checks every value given against its declaration (UsageError for an undeclared name or a
  // bad value), then makes the factory.
  AllocatorFactory make_factory(std::string_view name, const Mdp& mdp, const ParameterValues& values = {}) const;

  // The same for a problem acting while planning (SPEC §10): the kind's own concurrent allocators
  // or its eager rule. Throws UsageError for a kind without a commit rule, naming those with one.
  ConcurrentAllocatorFactory make_concurrent_factory(std::string_view name, const ConcurrentMdp& mdp,
                                                     const ParameterValues& values = {}) const;
  // Names of the kinds that act while planning, in registration order.
  std::vector<std::string> acting_names() const;

  // The budget of each decision that `values` ask of kind `name` (unset when they ask for none,
  // or when the kind takes no budget). Throws UsageError for a bad value.
  DecisionBudget decision_budget(std::string_view name, const ParameterValues& values) const;

  // The memory that running kind `name` on `problem` may hold at most with `allocators`
  // allocators at once (one per thread), in bytes; 0 when it declares none.
  double memory_bytes(std::string_view name, const Problem& problem, const ParameterValues& values,
                      std::uint64_t allocators) const;
  // Throws UsageError "SPELLED VALUE[ with N threads]: would need up to X GiB of memory, Y GiB
  // available" (util/memory.hpp) when that memory exceeds what this process can have, before
  // any long work starts.
  void check_memory(std::string_view name, const Problem& problem, const ParameterValues& values,
                    std::uint64_t allocators, const ParameterSpelling& spelling = nullptr) const;

  // Adds a kind (tests and extensions may add their own). Throws UsageError when the name is
  // taken or a parameter contradicts another kind's declaration of the same name.
  void add(AllocatorKind kind);
  // Removes a kind added by add() (tests clean up after themselves).
  void remove(std::string_view name);

 private:
  std::vector<AllocatorKind> kinds_;
};

// The process-wide registry, holding the built-in kinds. Not synchronised: add kinds before
// using it from several threads.
AllocatorRegistry& allocator_registry();

// Iterations per search in `statistics` of an allocator of `kind`, when the kind declares both
// counters (a searcher); nothing otherwise, or when it ran no search.
std::optional<double> iterations_per_search(const AllocatorKind& kind, const Statistics& statistics);

// The commit rule of the kinds that choose a skeleton plan-first (EagerCommitAllocator).
inline constexpr const char* kEagerCommitRule =
    "eager: starts the next action of the skeleton it chooses as soon as that action is refined, the robot is idle "
    "and (chains, expiry) the action may start; a complete plan runs at once";

// Shorthand for allocator_registry().make_concurrent_factory(...).
ConcurrentAllocatorFactory make_concurrent_allocator_factory(std::string_view name, const ConcurrentMdp& mdp,
                                                             const ParameterValues& values = {});

// Shorthand for allocator_registry().make_factory(...).
AllocatorFactory make_allocator_factory(std::string_view name, const Mdp& mdp, const ParameterValues& values = {});

}  // namespace ontime
