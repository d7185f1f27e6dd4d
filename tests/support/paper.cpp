#include "support/paper.hpp"

#include <string>
#include <vector>

#include "ontime/model/instance_io.hpp"

namespace ontime::testing {

std::filesystem::path source_path(const std::string& relative) {
  return std::filesystem::path(ONTIME_SOURCE_DIR) / relative;
}

Problem navigation_with_deadline(Steps deadline) {
  const Problem navigation = load_problem(source_path("data/instances/navigation.json"));
  std::vector<std::vector<int>> skeletons;
  for (int k = 0; k < navigation.skeleton_count(); ++k) {
    skeletons.emplace_back(navigation.skeleton(k).begin(), navigation.skeleton(k).end());
  }
  return {"navigation-" + std::to_string(deadline), deadline, navigation.step_seconds(),
          std::vector<Action>(navigation.actions().begin(), navigation.actions().end()), skeletons};
}

Problem paper_instance(const std::string& name) {
  return load_problem(source_path("data/instances/paper/" + name + ".json"));
}

const std::array<PublishedRow, 5> kTableOne{{
    {{0.98, 0.02}, {0.93, 0.05}, {0.94, 0.05}, {0.72, 0.09}, {0.37, 0.09}, {0.92, 0.05}},
    {{0.74, 0.09}, {0.65, 0.09}, {0.70, 0.09}, {0.37, 0.09}, {0.51, 0.09}, {0.65, 0.09}},
    {{0.71, 0.09}, {0.35, 0.09}, {0.67, 0.09}, {0.25, 0.08}, {0.59, 0.09}, {0.34, 0.09}},
    {{0.94, 0.05}, {0.90, 0.06}, {0.90, 0.06}, {0.79, 0.08}, {0.45, 0.09}, {0.54, 0.09}},
    {{0.71, 0.09}, {0.33, 0.09}, {0.70, 0.09}, {0.10, 0.06}, {0.70, 0.09}, {0.34, 0.09}},
}};

}  // namespace ontime::testing
