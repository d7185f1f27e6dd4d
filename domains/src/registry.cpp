#include "ontime/domains/registry.hpp"

#include <stdexcept>

#include "ontime/domains/manipulation.hpp"
#include "ontime/domains/manipulation_features.hpp"
#include "ontime/domains/navigation.hpp"
#include "ontime/domains/navigation_features.hpp"
#include "ontime/util/error.hpp"

namespace ontime::domains {

std::string Domain::describe(const std::vector<std::string>& skeleton) const {
  std::string text;
  for (const std::string& action : skeleton) text += (text.empty() ? "" : " ") + action;
  return text;
}

std::vector<StandaloneAction> Domain::every_action() const { return {}; }

const std::vector<std::string>& Domain::feature_names() const {
  static const std::vector<std::string> none;
  return none;
}

std::vector<double> Domain::action_features(const std::string& /*action*/) const {
  throw std::invalid_argument("the " + name() + " domain has no features for conditional time models");
}

std::vector<std::string> domain_names() { return {"navigation", "manipulation"}; }

std::vector<std::string> domain_feature_names(std::string_view name) {
  if (name == "navigation") return navigation_feature_names();
  if (name == "manipulation") return manipulation_feature_names();
  throw unknown_name_error("domain", name, domain_names());
}

LoadedDomain load_domain(std::string_view name, const std::filesystem::path& world_file) {
  if (name == "navigation") {
    NavigationWorld world = load_navigation_world(world_file);
    const DomainDefaults defaults{world.collection};
    return LoadedDomain{std::make_unique<NavigationDomain>(std::move(world)), defaults};
  }
  if (name == "manipulation") {
    ManipulationWorld world = load_manipulation_world(world_file);
    const DomainDefaults defaults{world.collection};
    return LoadedDomain{std::make_unique<ManipulationDomain>(std::move(world)), defaults};
  }
  throw unknown_name_error("domain", name, domain_names());
}

EffortSettings effort_settings(const DomainDefaults& defaults, std::string_view unit, double checks_per_second) {
  EffortSettings effort;
  effort.unit = parse_effort_unit(unit);
  effort.checks_per_second = checks_per_second > 0 ? checks_per_second : defaults.collection.checks_per_second;
  return effort;
}

}  // namespace ontime::domains
