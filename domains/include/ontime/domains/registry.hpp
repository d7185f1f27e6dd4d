#pragma once
// Domains by name, for the command line and Python: loading one from its world file, and the
// settings the world file gives the commands that run it.

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/domains/domain.hpp"
#include "ontime/domains/effort.hpp"
#include "ontime/domains/world_types.hpp"

namespace ontime::domains {

// Names of the domains that can be loaded: "navigation", "manipulation".
std::vector<std::string> domain_names();

// The names of the named domain's action features (Domain::feature_names, without a world), the
// names a conditional time model of its worlds is fitted with. UsageError for an unknown domain
// or one without features.
std::vector<std::string> domain_feature_names(std::string_view name);

// Settings a domain's world file carries besides the world itself.
struct DomainDefaults {
  CollectionDefaults collection;
};

struct LoadedDomain {
  std::unique_ptr<Domain> domain;
  DomainDefaults defaults;
};

// Loads the named domain from its world file. Throws ontime::UsageError for an unknown name
// and ontime::InputError for a bad world file.
LoadedDomain load_domain(std::string_view name, const std::filesystem::path& world_file);

// The effort settings of a run or a collection: the unit by name ("checks" or "wall"; UsageError
// otherwise) and `checks_per_second`, or the world file's when it is 0.
EffortSettings effort_settings(const DomainDefaults& defaults, std::string_view unit, double checks_per_second = 0);

}  // namespace ontime::domains
