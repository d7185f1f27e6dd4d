#pragma once
// Internal: reading a chain's fields ("states", "start", "transitions"), shared by the chain-file
// reader (at the file's top level) and the instance reader (at `chains.NAME`, SPEC §9). Every rule
// broken raises InputError naming the source, the JSON path under `path` and the rule.

#include <nlohmann/json.hpp>
#include <string>

#include "ontime/model/exogenous_chain.hpp"

namespace ontime::detail {

// `object` must be a JSON object holding the three fields (other keys are the caller's to check).
ExogenousChain read_chain_fields(const nlohmann::ordered_json& object, const std::string& path, std::string name,
                                 const std::string& source);

}  // namespace ontime::detail
