#pragma once
// `ontime predict` (ontime.domains.predict): the instance of a world never refined before, every
// action's distributions predicted by a conditional time model from the action's features in
// that world (docs/learning.md). Milliseconds for a building of 30 rooms: the features are
// geometry and the model one evaluation per action.

#include <string>

#include "ontime/domains/domain.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/learn/conditional_model.hpp"
#include "ontime/model/problem.hpp"

namespace ontime::domains {

struct PredictOptions {
  Steps deadline = 0;    // 0: the world file's
  bool library = false;  // every action on its own even when the world lists skeletons
  std::string name;      // of the instance; empty: the domain's scene title
  // Threads computing the actions' features (0: one per hardware thread). The instance is the
  // same for every count: each action's features come from the world alone.
  unsigned threads = 0;
};

// The world's skeletons (or, with `library` or a world without skeletons, every action of
// Domain::every_action as a skeleton of its own), each action predicted by `model` in whole steps
// of the model's step. Each distinct action's features are computed once (skeletons share their
// prefixes), on `threads` threads: a kitchen's take thousands of IK draws per action. Throws UsageError when the model
// was fitted on other features (another domain, or another version of its extractor) or the world's step differs from
// the model's, or the domain has no features, or an action cannot be described, or every action on its own is asked of
// a domain that cannot list them (the kitchen); InputError is left to loading.
Problem predict_instance(const Domain& domain, const DomainDefaults& defaults, const ConditionalTimeModel& model,
                         const PredictOptions& options);

}  // namespace ontime::domains
