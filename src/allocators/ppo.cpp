#include "ontime/allocators/ppo.hpp"

#include <string>

#include "allocators/detail/ppo_networks.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/util/error.hpp"

namespace ontime {

int feature_count(int skeleton_count, int chain_inputs) noexcept { return 1 + 3 * skeleton_count + chain_inputs; }

int chain_feature_count(const Problem& problem) noexcept {
  if (!problem.is_timed()) return 0;
  int count = problem.timed_slot_count();
  for (const ExogenousChain& chain : problem.chains()) count += chain.state_count();
  return count;
}

void normalised_state(const Mdp& mdp, const State& state, std::span<float> out) noexcept {
  const Problem& problem = mdp.problem();
  const int count = mdp.skeleton_count();
  const auto deadline = static_cast<float>(mdp.deadline());
  out[0] = static_cast<float>(state.time) / deadline;
  for (int k = 0; k < count; ++k) {
    const auto slot = static_cast<std::size_t>(k);
    const auto base = 3 * slot;
    out[base + 1] = static_cast<float>(state.refined[slot]) / static_cast<float>(problem.skeleton_length(k));
    out[base + 2] = static_cast<float>(state.spent[slot]) / deadline;
    out[base + 3] = static_cast<float>(state.execution[slot]) / deadline;
  }
  if (!mdp.is_timed()) return;
  auto at = static_cast<std::size_t>(feature_count(count));
  const auto chains = static_cast<int>(problem.chains().size());
  for (int c = 0; c < chains; ++c) {
    const int states = problem.chains()[static_cast<std::size_t>(c)].state_count();
    const int current = mdp.chain_state(state.chains, c);
    for (int s = 0; s < states; ++s) out[at++] = s == current ? 1.0F : 0.0F;
  }
  // The timed slots follow the culprits' in State::restore.
  const int first = problem.culprit_slot_count();
  for (int slot = first; slot < first + problem.timed_slot_count(); ++slot) {
    out[at++] = static_cast<float>(state.restore[static_cast<std::size_t>(slot)]) / deadline;
  }
}

void state_features(const Mdp& mdp, const State& state, PolicyNetwork::Vector& features) {
  features.resize(feature_count(mdp.skeleton_count(), chain_feature_count(mdp.problem())));
  normalised_state(mdp, state, std::span<float>(features.data(), static_cast<std::size_t>(features.size())));
}

struct PpoAllocator::Evaluation {
  PolicyNetwork actor;
  PolicyNetwork::Vector features;
};

PpoAllocator::PpoAllocator(const Mdp& mdp, std::shared_ptr<const PpoPolicy> policy)
    : mdp_(&mdp), policy_(std::move(policy)) {
  if (!policy_ || !policy_->networks) throw UsageError("the ppo policy holds no trained networks");
  if (policy_->skeleton_count != mdp.skeleton_count() || policy_->deadline != mdp.deadline()) {
    throw UsageError("the ppo policy was trained for " + std::to_string(policy_->skeleton_count) +
                     " skeletons and deadline " + std::to_string(policy_->deadline) + " ('" + policy_->instance +
                     "'), not for this instance (" + std::to_string(mdp.skeleton_count()) + " skeletons, deadline " +
                     std::to_string(mdp.deadline()) + ")");
  }
  if (policy_->chain_inputs != chain_feature_count(mdp.problem())) {
    throw UsageError("the ppo policy was trained with " + std::to_string(policy_->chain_inputs) +
                     " inputs for exogenous chains and timed actions ('" + policy_->instance +
                     "'), this instance has " + std::to_string(chain_feature_count(mdp.problem())) +
                     " (SPEC §9): retrain it on this instance");
  }
  evaluation_ = std::make_unique<Evaluation>(Evaluation{policy_->networks->actor, {}});
}

PpoAllocator::~PpoAllocator() = default;

int PpoAllocator::choose(const State& state) {
  const ChoiceList choices = mdp_->useful_choices(state);
  if (choices.empty()) return mdp_->first_with_work_left(state);
  state_features(*mdp_, state, evaluation_->features);
  const PolicyNetwork::Vector& logits = evaluation_->actor.evaluate(evaluation_->features);
  int best = choices[0];
  for (const int choice : choices) {
    if (logits(choice) > logits(best)) best = choice;
  }
  return best;
}

namespace {

// Refuses a policy unless it records the digest of `problem` (what it was trained on).
void check_trained_on(const PpoPolicy& policy, const Problem& problem, const std::string& file) {
  constexpr const char* kOverride =
      "; to use it anyway on an instance of the same skeleton count and deadline, set "
      "the parameter 'policy-check' to 'shape' (--policy-check shape)";
  if (policy.instance_digest.empty()) {
    throw UsageError("policy " + file +
                     " records no digest of the instance it was trained on (it predates digests): retrain it with "
                     "'ontime train'" +
                     kOverride);
  }
  const std::string digest = instance_digest(problem);
  if (policy.instance_digest != digest) {
    throw UsageError("policy " + file + " was trained on another instance ('" + policy.instance + "', " +
                     policy.instance_digest + ") than this one ('" + problem.name() + "', " + digest +
                     "): retrain it on this instance" + kOverride);
  }
}

}  // namespace

AllocatorKind ppo_kind() {
  return {.name = "ppo",
          .summary = "a policy learned by Proximal Policy Optimization from episodes alone, acting greedily",
          .capabilities = {Capability::stationary, Capability::needs_policy, Capability::chains},
          .parameters = {Parameter::path(
                             "policy", "trained policy file (JSON); for several instances, one per instance in order"),
                         Parameter::choice(
                             "policy-check", "digest", {"digest", "shape"},
                             "accept policies trained on this instance only, or any of its size and deadline")},
          .make = [](const Mdp& mdp, const ParameterReader& parameters) -> AllocatorFactory {
            if (!parameters.given("policy")) {
              throw UsageError(
                  "ppo needs a trained policy: its parameter 'policy' names the file of a policy trained for this "
                  "instance");
            }
            const std::string file = parameters.text("policy");
            auto policy = std::make_shared<const PpoPolicy>(load_ppo_policy(file));
            PpoAllocator probe(mdp, policy);  // fails here when the policy is for another shape of instance
            if (parameters.text("policy-check") == "digest") check_trained_on(*policy, mdp.problem(), file);
            return [model = &mdp, policy] { return std::make_unique<PpoAllocator>(*model, policy); };
          }};
}

}  // namespace ontime
