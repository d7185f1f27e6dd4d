#include "ontime/domains/predict.hpp"

#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <unordered_set>

#include "ontime/util/error.hpp"
#include "ontime/util/parallel.hpp"

namespace ontime::domains {

Problem predict_instance(const Domain& domain, const DomainDefaults& defaults, const ConditionalTimeModel& model,
                         const PredictOptions& options) {
  if (domain.feature_names().empty()) {
    throw UsageError("the " + domain.name() + " domain has no features for conditional time models");
  }
  if (model.feature_names() != domain.feature_names()) {
    std::string names;
    for (const std::string& name : model.feature_names()) names += (names.empty() ? "" : ", ") + name;
    throw UsageError("the model was fitted on other features (" + names + ") than the " + domain.name() +
                     " domain's; fit it with --domain " + domain.name());
  }
  // (A relative slack: the step is written as a decimal in both files.)
  if (std::abs(model.step_seconds() - defaults.collection.step_seconds) > 1e-9 * defaults.collection.step_seconds) {
    throw UsageError("the model's step is " + std::to_string(model.step_seconds()) + " s, the world's " +
                     std::to_string(defaults.collection.step_seconds) + " s");
  }
  std::vector<std::vector<std::string>> skeletons;
  std::vector<std::string> ids;
  if (!options.library && !domain.skeletons().empty()) {
    skeletons = domain.skeletons();
    for (const auto& skeleton : skeletons) ids.insert(ids.end(), skeleton.begin(), skeleton.end());
  } else {
    for (const StandaloneAction& action : domain.every_action()) ids.push_back(action.action);
    if (ids.empty()) {
      throw UsageError("the " + domain.name() +
                       " domain cannot list every action it refines: predict the world's skeletons instead (without "
                       "--library)");
    }
  }
  // Each action once, in the order of its first appearance.
  std::vector<ActionFeatures> actions;
  std::unordered_set<std::string> seen;
  for (const std::string& id : ids) {
    if (seen.insert(id).second) actions.push_back({id, {}});
  }
  // An action that cannot be described: the first in that order is reported, whichever thread
  // met it first.
  std::vector<std::optional<std::string>> refusals(actions.size());
  for_each_block(actions.size(), options.threads, 1, [&](unsigned /*thread*/) {
    return [&](std::uint64_t begin, std::uint64_t end) {
      for (std::uint64_t a = begin; a < end; ++a) {
        try {
          actions[a].features = domain.action_features(actions[a].id);
        } catch (const std::invalid_argument& error) {
          refusals[a] = error.what();
        }
      }
    };
  });
  for (const std::optional<std::string>& refusal : refusals) {
    if (refusal) throw UsageError(*refusal);
  }
  const Steps deadline = options.deadline > 0 ? options.deadline : defaults.collection.deadline;
  return predict_problem(model, actions, skeletons, deadline,
                         options.name.empty() ? domain.scene().title : options.name,
                         "Predicted by a " + model.kind() + " conditional time model from the world's geometry");
}

}  // namespace ontime::domains
