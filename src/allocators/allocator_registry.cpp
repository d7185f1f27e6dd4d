#include "ontime/allocators/allocator_registry.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <system_error>
#include <utility>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

constexpr Capability kAllCapabilities[] = {Capability::stationary,   Capability::randomised, Capability::anytime,
                                           Capability::needs_policy, Capability::optimal,    Capability::certified,
                                           Capability::chains};

// The whole text as a number of the parameter's type, or nothing.
std::optional<double> parse_number(const Parameter& parameter, std::string_view text) {
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (parameter.type == ParameterType::integer) {
    std::uint64_t value = 0;
    const auto [end, error] = std::from_chars(first, last, value);
    if (error != std::errc() || end != last) return std::nullopt;
    return static_cast<double>(value);
  }
  double value = 0;
  const auto [end, error] = std::from_chars(first, last, value);
  if (error != std::errc() || end != last || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace

std::vector<std::string> Capabilities::names() const {
  std::vector<std::string> out;
  for (const Capability capability : kAllCapabilities) {
    if (has(capability)) out.emplace_back(to_string(capability));
  }
  return out;
}

std::string_view to_string(Capability capability) noexcept {
  switch (capability) {
    case Capability::stationary:
      return "stationary";
    case Capability::randomised:
      return "randomised";
    case Capability::anytime:
      return "anytime";
    case Capability::needs_policy:
      return "needs-policy";
    case Capability::optimal:
      return "optimal";
    case Capability::certified:
      return "certified";
    case Capability::chains:
      return "chains";
  }
  return "?";
}

std::string_view to_string(ParameterType type) noexcept {
  switch (type) {
    case ParameterType::integer:
      return "integer";
    case ParameterType::real:
      return "real";
    case ParameterType::text:
      return "text";
    case ParameterType::choice:
      return "choice";
    case ParameterType::path:
      return "path";
  }
  return "?";
}

Parameter Parameter::integer(std::string name, std::uint64_t default_value, double minimum, double maximum,
                             std::string help) {
  return Parameter{std::move(name), ParameterType::integer, std::to_string(default_value), minimum, maximum, {},
                   std::move(help)};
}

Parameter Parameter::real(std::string name, double default_value, double minimum, double maximum, std::string help) {
  return Parameter{std::move(name), ParameterType::real, fmt::format("{}", default_value), minimum, maximum, {},
                   std::move(help)};
}

Parameter Parameter::choice(std::string name, std::string default_value, std::vector<std::string> choices,
                            std::string help) {
  return Parameter{std::move(name), ParameterType::choice, std::move(default_value), -kNoLimit,
                   kNoLimit,        std::move(choices),    std::move(help)};
}

Parameter Parameter::text(std::string name, std::string default_value, std::string help) {
  return Parameter{std::move(name), ParameterType::text, std::move(default_value), -kNoLimit, kNoLimit, {},
                   std::move(help)};
}

Parameter Parameter::path(std::string name, std::string help) {
  return Parameter{std::move(name), ParameterType::path, "", -kNoLimit, kNoLimit, {}, std::move(help)};
}

std::string Parameter::allowed() const {
  if (type == ParameterType::choice) return fmt::format("one of {}", fmt::join(choices, ", "));
  if (type != ParameterType::integer && type != ParameterType::real) return "";
  const bool low = std::isfinite(minimum);
  const bool high = std::isfinite(maximum);
  if (low && high) return fmt::format("in [{}, {}]", minimum, maximum);
  if (low) return fmt::format(">= {}", minimum);
  if (high) return fmt::format("<= {}", maximum);
  return "";
}

std::optional<std::string> Parameter::violation(std::string_view value) const {
  const auto rule = [&](const std::string& text) { return fmt::format("{} (got '{}')", text, value); };
  switch (type) {
    case ParameterType::integer:
    case ParameterType::real: {
      const std::optional<double> number = parse_number(*this, value);
      const std::string what = type == ParameterType::integer ? "a whole number" : "a finite number";
      const std::string range = allowed();
      if (!number || *number < minimum || *number > maximum)
        return rule("must be " + what + (range.empty() ? "" : " " + range));
      return std::nullopt;
    }
    case ParameterType::choice:
      if (std::find(choices.begin(), choices.end(), value) == choices.end()) {
        return rule("must be " + allowed());
      }
      return std::nullopt;
    case ParameterType::path:
      if (value.empty()) return rule("must name a file");
      return std::nullopt;
    case ParameterType::text:
      return std::nullopt;
  }
  return std::nullopt;
}

void Parameter::check(std::string_view value) const {
  if (const std::optional<std::string> rule = violation(value)) {
    throw UsageError("parameter '" + name + "': " + *rule);
  }
}

const std::string* ParameterValues::find(std::string_view name) const {
  const auto found = values_.find(name);
  return found == values_.end() ? nullptr : &found->second;
}

const Parameter& ParameterReader::declared(std::string_view name) const {
  for (const Parameter& parameter : kind_->parameters) {
    if (parameter.name == name) return parameter;
  }
  // A kind reading a parameter it did not declare is a defect of that kind.
  throw std::logic_error("allocator '" + kind_->name + "' reads undeclared parameter '" + std::string(name) + "'");
}

bool ParameterReader::given(std::string_view name) const {
  declared(name);
  return values_->find(name) != nullptr;
}

std::string ParameterReader::raw(std::string_view name) const {
  const Parameter& parameter = declared(name);
  const std::string* value = values_->find(name);
  return value != nullptr ? *value : parameter.default_value;
}

double ParameterReader::real(std::string_view name) const {
  const Parameter& parameter = declared(name);
  const std::string text = raw(name);
  const std::optional<double> number = parse_number(parameter, text);
  if (!number) throw UsageError("allocator '" + kind_->name + "' needs its parameter '" + std::string(name) + "'");
  return *number;
}

std::uint64_t ParameterReader::integer(std::string_view name) const {
  const std::string text = raw(name);
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) {
    throw UsageError("allocator '" + kind_->name + "' needs its parameter '" + std::string(name) + "'");
  }
  return value;
}

std::string ParameterReader::text(std::string_view name) const { return raw(name); }

std::vector<std::string> AllocatorRegistry::names() const {
  std::vector<std::string> out;
  for (const AllocatorKind& kind : kinds_) out.push_back(kind.name);
  return out;
}

std::vector<std::string> AllocatorRegistry::names(Capabilities with, Capabilities without) const {
  std::vector<std::string> out;
  for (const AllocatorKind& kind : kinds_) {
    bool keep = true;
    for (const Capability capability : kAllCapabilities) {
      if (with.has(capability) && !kind.capabilities.has(capability)) keep = false;
      if (without.has(capability) && kind.capabilities.has(capability)) keep = false;
    }
    if (keep) out.push_back(kind.name);
  }
  return out;
}

const AllocatorKind& AllocatorRegistry::find(std::string_view name) const {
  for (const AllocatorKind& kind : kinds_) {
    if (kind.name == name) return kind;
  }
  throw unknown_name_error("allocator", name, names());
}

std::vector<Parameter> AllocatorRegistry::parameters() const {
  std::vector<Parameter> out;
  for (const AllocatorKind& kind : kinds_) {
    for (const Parameter& parameter : kind.parameters) {
      const bool seen =
          std::any_of(out.begin(), out.end(), [&](const Parameter& p) { return p.name == parameter.name; });
      if (!seen) out.push_back(parameter);
    }
  }
  return out;
}

std::vector<std::string> AllocatorRegistry::kinds_with_parameter(std::string_view name) const {
  std::vector<std::string> out;
  for (const AllocatorKind& kind : kinds_) {
    for (const Parameter& parameter : kind.parameters) {
      if (parameter.name == name) out.push_back(kind.name);
    }
  }
  return out;
}

namespace {

// Checks every value given against its declaration, as make_factory does.
void check_values(const AllocatorRegistry& kinds, const ParameterValues& values) {
  const std::vector<Parameter> declared = kinds.parameters();
  for (const auto& entry : values.all()) {
    // A named reference, not a structured binding: clang 14 cannot capture bindings in a lambda.
    const std::string& given = entry.first;
    const auto parameter =
        std::find_if(declared.begin(), declared.end(), [&](const Parameter& p) { return p.name == given; });
    if (parameter == declared.end()) {
      std::vector<std::string> known;
      known.reserve(declared.size());
      for (const Parameter& p : declared) known.push_back(p.name);
      throw unknown_name_error("allocator parameter", given, known);
    }
    parameter->check(entry.second);
  }
}

}  // namespace

AllocatorFactory AllocatorRegistry::make_factory(std::string_view name, const Mdp& mdp,
                                                 const ParameterValues& values) const {
  const AllocatorKind& kind = find(name);
  check_values(*this, values);
  if (mdp.is_timed() && !kind.capabilities.has(Capability::chains)) {
    throw UsageError(
        fmt::format("allocator '{}' does not take instances with exogenous chains or expiry (SPEC §9) yet; {} do",
                    kind.name, fmt::join(names({Capability::chains}, {}), ", ")));
  }
  return kind.make(mdp, ParameterReader(kind, values));
}

ConcurrentAllocatorFactory AllocatorRegistry::make_concurrent_factory(std::string_view name, const ConcurrentMdp& mdp,
                                                                      const ParameterValues& values) const {
  const AllocatorKind& kind = find(name);
  check_values(*this, values);
  if (!kind.acts_while_planning()) {
    throw UsageError(fmt::format(
        "allocator '{}' does not act while planning (SPEC §10) yet: it has no commit rule; {} do (--act plan-first "
        "takes every allocator)",
        kind.name, fmt::join(acting_names(), ", ")));
  }
  const ParameterReader reader(kind, values);
  if (kind.make_concurrent) return kind.make_concurrent(mdp, reader);
  return eager_commit_factory(mdp, kind.make(mdp.plan_first_mdp(), reader));
}

std::vector<std::string> AllocatorRegistry::acting_names() const {
  std::vector<std::string> out;
  for (const AllocatorKind& kind : kinds_) {
    if (kind.acts_while_planning()) out.push_back(kind.name);
  }
  return out;
}

DecisionBudget AllocatorRegistry::decision_budget(std::string_view name, const ParameterValues& values) const {
  const AllocatorKind& kind = find(name);
  if (!kind.needs.decision_budget) return {};
  return kind.needs.decision_budget(ParameterReader(kind, values));
}

double AllocatorRegistry::memory_bytes(std::string_view name, const Problem& problem, const ParameterValues& values,
                                       std::uint64_t allocators) const {
  const AllocatorKind& kind = find(name);
  const MemoryNeed& memory = kind.needs.memory;
  if (!memory.bytes) return 0;
  const double each = memory.bytes(problem, ParameterReader(kind, values));
  return memory.per_allocator ? each * static_cast<double>(std::max<std::uint64_t>(allocators, 1)) : each;
}

void AllocatorRegistry::check_memory(std::string_view name, const Problem& problem, const ParameterValues& values,
                                     std::uint64_t allocators, const ParameterSpelling& spelling) const {
  const AllocatorKind& kind = find(name);
  const MemoryNeed& memory = kind.needs.memory;
  if (!memory.bytes) return;
  const ParameterReader reader(kind, values);
  std::string what =
      spell_parameter(spelling, memory.parameter) + " " + std::to_string(reader.integer(memory.parameter));
  if (memory.per_allocator) {
    allocators = std::max<std::uint64_t>(allocators, 1);
    what += " with " + std::to_string(allocators) + (allocators == 1 ? " thread" : " threads");
  }
  check_memory_for(what, memory_bytes(name, problem, values, allocators));
}

bool AllocatorKind::declares_counter(std::string_view counter) const {
  return std::any_of(needs.counters.begin(), needs.counters.end(),
                     [&](const CounterDeclaration& declared) { return declared.name == counter; });
}

std::optional<double> iterations_per_search(const AllocatorKind& kind, const Statistics& statistics) {
  if (!kind.declares_counter(kSearchesCounter) || !kind.declares_counter(kIterationsCounter)) return std::nullopt;
  const double searches = statistics.find(kSearchesCounter).value_or(0.0);
  if (searches <= 0) return std::nullopt;
  return statistics.find(kIterationsCounter).value_or(0.0) / searches;
}

void AllocatorRegistry::add(AllocatorKind kind) {
  if (kind.name.empty() || !kind.make) throw UsageError("an allocator kind needs a name and a way to make it");
  if (std::any_of(kinds_.begin(), kinds_.end(), [&](const AllocatorKind& k) { return k.name == kind.name; })) {
    throw UsageError("allocator '" + kind.name + "' is registered already");
  }
  const std::vector<Parameter> known = parameters();
  for (const Parameter& parameter : kind.parameters) {
    if (!parameter.default_value.empty()) parameter.check(parameter.default_value);
    for (const Parameter& other : known) {
      if (other.name == parameter.name &&
          (other.type != parameter.type || other.default_value != parameter.default_value ||
           other.minimum != parameter.minimum || other.maximum != parameter.maximum ||
           other.choices != parameter.choices)) {
        throw UsageError("allocator '" + kind.name + "' declares parameter '" + parameter.name +
                         "' unlike the kinds that declare it already");
      }
    }
  }
  kinds_.push_back(std::move(kind));
}

void AllocatorRegistry::remove(std::string_view name) {
  std::erase_if(kinds_, [&](const AllocatorKind& kind) { return kind.name == name; });
}

// The built-in kinds: each allocator's source file defines NAME_kind(); this list (one line per
// kind, in the order of the paper's tables) is the only place that names them all.
#define ONTIME_ALLOCATOR_KIND(identifier) AllocatorKind identifier##_kind();
#include "allocators/kinds.inc"
#undef ONTIME_ALLOCATOR_KIND

AllocatorRegistry& allocator_registry() {
  static AllocatorRegistry registry = [] {
    AllocatorRegistry built_in;
#define ONTIME_ALLOCATOR_KIND(identifier) built_in.add(identifier##_kind());
#include "allocators/kinds.inc"
#undef ONTIME_ALLOCATOR_KIND
    return built_in;
  }();
  return registry;
}

ConcurrentAllocatorFactory make_concurrent_allocator_factory(std::string_view name, const ConcurrentMdp& mdp,
                                                             const ParameterValues& values) {
  return allocator_registry().make_concurrent_factory(name, mdp, values);
}

AllocatorFactory make_allocator_factory(std::string_view name, const Mdp& mdp, const ParameterValues& values) {
  return allocator_registry().make_factory(name, mdp, values);
}

}  // namespace ontime
