#include "ontime/model/skeleton_file.hpp"

#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "model/skeleton_list.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime {
namespace {
using Json = nlohmann::ordered_json;
}  // namespace

SkeletonList parse_skeleton_file(std::string_view text, std::string_view source) {
  const std::string name(source);
  const Json root = detail::parse_json_strict<Json>(text, name);
  if (!root.is_object()) {
    throw InputError(name, "top level",
                     "must be a JSON object with a 'skeletons' member (got " + detail::describe_json_type(root) + ")");
  }
  if (!root.contains("skeletons")) throw InputError(name, "top level", "missing required key 'skeletons'");
  std::vector<std::string> ids;
  std::map<std::string, int> index_of;
  const std::vector<std::vector<int>> indices = detail::read_skeleton_list(
      root["skeletons"], name,
      [&](const std::string& id) -> std::optional<int> {
        const auto [entry, fresh] = index_of.try_emplace(id, static_cast<int>(ids.size()));
        if (fresh) ids.push_back(id);
        return entry->second;
      },
      [&ids](int index) { return ids[static_cast<std::size_t>(index)]; });
  SkeletonList list;
  list.source = name;
  for (const std::vector<int>& skeleton : indices) {
    std::vector<std::string>& named = list.skeletons.emplace_back();
    for (const int index : skeleton) named.push_back(ids[static_cast<std::size_t>(index)]);
  }
  return list;
}

SkeletonList load_skeleton_file(const std::filesystem::path& path) {
  return parse_skeleton_file(read_input_file(path, "skeleton"), path.string());
}

}  // namespace ontime
