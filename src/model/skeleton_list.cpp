#include "model/skeleton_list.hpp"

#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "ontime/model/problem.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime::detail {

std::vector<std::vector<int>> read_skeleton_list(const nlohmann::ordered_json& list, const std::string& source,
                                                 const std::function<std::optional<int>(const std::string&)>& resolve,
                                                 const std::function<std::string(int)>& id_of) {
  using Json = nlohmann::ordered_json;
  const auto fail = [&source](const std::string& place, const std::string& rule) {
    throw InputError(source, place, rule);
  };
  if (!list.is_array()) fail("skeletons", "must be an array of skeletons (got " + describe_json_type(list) + ")");
  if (list.empty()) fail("skeletons", "at least one skeleton is needed");
  if (list.size() > static_cast<std::size_t>(Problem::kMaxSkeletons)) {
    fail("skeletons", "at most " + std::to_string(Problem::kMaxSkeletons) + " skeletons are supported (got " +
                          std::to_string(list.size()) + ")");
  }
  struct Occurrence {
    std::size_t skeleton, position;
  };
  std::map<int, Occurrence> first_use;
  std::map<std::vector<int>, std::size_t> seen_skeletons;
  std::vector<std::vector<int>> skeletons;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string path = json_index("skeletons", k);
    const Json& skeleton_json = list[k];
    if (!skeleton_json.is_array()) {
      fail(path, "a skeleton must be an array of action ids (got " + describe_json_type(skeleton_json) + ")");
    }
    if (skeleton_json.empty()) fail(path, "a skeleton must list at least one action");
    if (skeleton_json.size() > static_cast<std::size_t>(Problem::kMaxSkeletonLength)) {
      fail(path, "a skeleton may list at most " + std::to_string(Problem::kMaxSkeletonLength) + " actions (got " +
                     std::to_string(skeleton_json.size()) + ")");
    }
    std::vector<int> skeleton;
    for (std::size_t l = 0; l < skeleton_json.size(); ++l) {
      const std::string place = json_index(path, l);
      const Json& id_json = skeleton_json[l];
      if (!id_json.is_string()) fail(place, "an action id must be a string (got " + describe_json_type(id_json) + ")");
      const std::string id = id_json.get<std::string>();
      if (id.empty()) fail(place, "action ids must be non-empty");
      const std::optional<int> known = resolve(id);
      if (!known) fail(place, "unknown action id '" + id + "' (not a key of 'actions')");
      const int action = *known;
      for (std::size_t earlier = 0; earlier < skeleton.size(); ++earlier) {
        if (skeleton[earlier] == action) {
          fail(place, "action '" + id + "' appears twice in one skeleton (also at " + json_index(path, earlier) + ")");
        }
      }
      const auto [use, first] = first_use.try_emplace(action, Occurrence{k, l});
      if (!first) {
        const Occurrence other = use->second;
        const std::string there = json_index(json_index("skeletons", other.skeleton), other.position);
        if (other.position != l) {
          fail(place, "action '" + id + "' is shared with " + there +
                          " at another position; shared actions must follow a common prefix (SPEC §1)");
        }
        const int parent_here = l == 0 ? -1 : skeleton[l - 1];
        const int parent_there = l == 0 ? -1 : skeletons[other.skeleton][l - 1];
        if (parent_here != parent_there) {
          fail(place, "action '" + id + "' is shared with " + there + " but the actions before it differ ('" +
                          id_of(parent_here) + "' here, '" + id_of(parent_there) +
                          "' there); shared actions must follow a common prefix (SPEC §1)");
        }
      }
      skeleton.push_back(action);
    }
    const auto [duplicate, fresh] = seen_skeletons.try_emplace(skeleton, k);
    if (!fresh) {
      fail(path, "the same skeleton as " + json_index("skeletons", duplicate->second) + "; list each skeleton once");
    }
    skeletons.push_back(std::move(skeleton));
  }
  return skeletons;
}

}  // namespace ontime::detail
