#pragma once
// Internal: reading and checking a JSON list of plan skeletons (SPEC §1, §5), shared by the
// instance reader and the skeleton-file reader. Every rule broken raises InputError naming the
// source, the JSON path (`skeletons[1][2]`) and the rule.

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace ontime::detail {

// `resolve(id)` gives the index of an action id, or nullopt for an id it does not know (which
// is then reported as unknown); `id_of(index)` gives the id back for messages.
std::vector<std::vector<int>> read_skeleton_list(const nlohmann::ordered_json& list, const std::string& source,
                                                 const std::function<std::optional<int>(const std::string&)>& resolve,
                                                 const std::function<std::string(int)>& id_of);

}  // namespace ontime::detail
