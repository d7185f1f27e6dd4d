#include "ontime/allocators/ppo.hpp"

#include <algorithm>
#include <string>
#include <vector>

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

int concurrent_feature_count(int skeleton_count, int chain_inputs) noexcept {
  return 2 + 6 * skeleton_count + chain_inputs;
}

int concurrent_chain_feature_count(const Problem& problem) noexcept {
  if (!problem.is_timed()) return 0;
  int count = 0;
  for (const ExogenousChain& chain : problem.chains()) count += chain.state_count();
  return count;
}

int concurrent_move_count(int skeleton_count) noexcept { return 2 * skeleton_count + 1; }

void concurrent_normalised_state(const ConcurrentMdp& mdp, const ConcurrentState& state, std::span<float> out) {
  const Problem& problem = mdp.problem();
  const int count = mdp.skeleton_count();
  const auto deadline = static_cast<float>(mdp.deadline());
  const std::int64_t too_late = std::int64_t{mdp.deadline()} + 1;
  const Steps time = ConcurrentMdp::time(state);
  out[0] = static_cast<float>(time) / deadline;
  out[1] = static_cast<float>(ConcurrentMdp::robot_left(state)) / deadline;
  const int depth = mdp.executed_depth(state);
  const std::vector<int> startable = mdp.startable(state);
  for (int k = 0; k < count; ++k) {
    const std::span<float> skeleton = out.subspan(2 + 6 * static_cast<std::size_t>(k), 6);
    if (!ConcurrentMdp::is_live(state, k)) {
      std::fill(skeleton.begin(), skeleton.end(), 0.0F);
      continue;
    }
    const auto length = static_cast<float>(problem.skeleton_length(k));
    const int refined = ConcurrentMdp::refined(state, k);
    skeleton[0] = 1.0F;
    skeleton[1] = static_cast<float>(depth) / length;
    skeleton[2] = static_cast<float>(refined) / length;
    skeleton[3] = static_cast<float>(mdp.spent(state, k)) / deadline;
    skeleton[4] = static_cast<float>(std::min(mdp.robot_free(state, k) - time, too_late)) / deadline;
    skeleton[5] = refined > depth && std::binary_search(startable.begin(), startable.end(), problem.action_at(k, depth))
                      ? 1.0F
                      : 0.0F;
  }
  if (!mdp.is_timed()) return;
  auto at = static_cast<std::size_t>(concurrent_feature_count(count));
  const Mdp& plan_first = mdp.plan_first_mdp();
  const auto chains = static_cast<int>(problem.chains().size());
  for (int c = 0; c < chains; ++c) {
    const int states = problem.chains()[static_cast<std::size_t>(c)].state_count();
    const int current = plan_first.chain_state(ConcurrentMdp::chains(state), c);
    for (int s = 0; s < states; ++s) out[at++] = s == current ? 1.0F : 0.0F;
  }
}

int ppo_move_output(const ConcurrentMdp& mdp, const ConcurrentState& state, const ConcurrentMdp::Move& move) noexcept {
  const int count = mdp.skeleton_count();
  if (!move.is_start()) return move.refine == ConcurrentMdp::kWait ? 2 * count : move.refine;
  const Problem& problem = mdp.problem();
  const int depth = mdp.executed_depth(state);
  for (int k = 0; k < count; ++k) {
    if (ConcurrentMdp::is_live(state, k) && depth < problem.skeleton_length(k) &&
        problem.action_at(k, depth) == move.start) {
      return count + k;
    }
  }
  return -1;
}

void state_features(const Mdp& mdp, const State& state, PolicyNetwork::Vector& features) {
  features.resize(feature_count(mdp.skeleton_count(), chain_feature_count(mdp.problem())));
  normalised_state(mdp, state, std::span<float>(features.data(), static_cast<std::size_t>(features.size())));
}

struct PpoAllocator::Evaluation {
  PolicyNetwork actor;
  PolicyNetwork::Vector features;
};

void concurrent_state_features(const ConcurrentMdp& mdp, const ConcurrentState& state,
                               PolicyNetwork::Vector& features) {
  features.resize(concurrent_feature_count(mdp.skeleton_count(), concurrent_chain_feature_count(mdp.problem())));
  concurrent_normalised_state(mdp, state, std::span<float>(features.data(), static_cast<std::size_t>(features.size())));
}

namespace {

// Refuses a policy that cannot drive an allocator of `acting` for an instance of `skeletons`,
// `deadline` and `chain_inputs`: no networks, trained in the other mode (networks of another shape
// and meaning), or for another shape of instance.
void check_fits(const PpoPolicy* policy, Acting acting, int skeletons, Steps deadline, int chain_inputs) {
  if (policy == nullptr || !policy->networks) throw UsageError("the ppo policy holds no trained networks");
  const auto mode = [](Acting a) {
    return std::string(a == Acting::concurrent ? "acting while planning" : "plan-first");
  };
  if (policy->acting != acting) {
    throw UsageError("the ppo policy was trained " + mode(policy->acting) + " ('" + policy->instance + "'), not " +
                     mode(acting) + " (SPEC §10): train it with --act " + std::string(acting_name(acting)));
  }
  if (policy->skeleton_count != skeletons || policy->deadline != deadline) {
    throw UsageError("the ppo policy was trained for " + std::to_string(policy->skeleton_count) +
                     " skeletons and deadline " + std::to_string(policy->deadline) + " ('" + policy->instance +
                     "'), not for this instance (" + std::to_string(skeletons) + " skeletons, deadline " +
                     std::to_string(deadline) + ")");
  }
  if (policy->chain_inputs != chain_inputs) {
    throw UsageError("the ppo policy was trained with " + std::to_string(policy->chain_inputs) + " inputs for " +
                     (acting == Acting::concurrent ? "exogenous chains" : "exogenous chains and timed actions") +
                     " ('" + policy->instance + "'), this instance has " + std::to_string(chain_inputs) +
                     " (SPEC §9): retrain it on this instance");
  }
}

}  // namespace

PpoAllocator::PpoAllocator(const Mdp& mdp, std::shared_ptr<const PpoPolicy> policy)
    : mdp_(&mdp), policy_(std::move(policy)) {
  check_fits(policy_.get(), Acting::plan_first, mdp.skeleton_count(), mdp.deadline(),
             chain_feature_count(mdp.problem()));
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

struct ConcurrentPpoAllocator::Evaluation {
  PolicyNetwork actor;
  PolicyNetwork::Vector features;
};

ConcurrentPpoAllocator::ConcurrentPpoAllocator(const ConcurrentMdp& mdp, std::shared_ptr<const PpoPolicy> policy)
    : mdp_(&mdp), policy_(std::move(policy)) {
  check_fits(policy_.get(), Acting::concurrent, mdp.skeleton_count(), mdp.deadline(),
             concurrent_chain_feature_count(mdp.problem()));
  evaluation_ = std::make_unique<Evaluation>(Evaluation{policy_->networks->actor, {}});
}

ConcurrentPpoAllocator::~ConcurrentPpoAllocator() = default;

ConcurrentMdp::Move ConcurrentPpoAllocator::choose(const ConcurrentState& state) {
  if (mdp_->certain_success(state)) return mdp_->run_complete_plan(state);
  const std::vector<ConcurrentMdp::Move> moves = mdp_->useful_moves(state);
  if (moves.empty()) return {};  // nothing can succeed any more
  concurrent_state_features(*mdp_, state, evaluation_->features);
  const PolicyNetwork::Vector& logits = evaluation_->actor.evaluate(evaluation_->features);
  // The most preferred output, its lowest index on ties (the moves' order is the solver's).
  ConcurrentMdp::Move best = moves.front();
  int best_output = -1;
  for (const ConcurrentMdp::Move& move : moves) {
    const int output = ppo_move_output(*mdp_, state, move);
    if (output < 0) continue;
    if (best_output < 0 || logits(output) > logits(best_output) ||
        (logits(output) == logits(best_output) && output < best_output)) {
      best = move;
      best_output = output;
    }
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

// The policy file the parameters name, checked for `mdp` by making an allocator of it (which refuses
// a policy of another mode or shape) and, unless policy-check is 'shape', by its digest.
template <class PolicyAllocator, class Model>
std::shared_ptr<const PpoPolicy> policy_for(const Model& mdp, const ParameterReader& parameters, const char* mode) {
  if (!parameters.given("policy")) {
    throw UsageError(
        std::string("ppo needs a trained policy: its parameter 'policy' names the file of a policy trained for this "
                    "instance") +
        mode);
  }
  const std::string file = parameters.text("policy");
  auto policy = std::make_shared<const PpoPolicy>(load_ppo_policy(file));
  PolicyAllocator probe(mdp, policy);
  if (parameters.text("policy-check") == "digest") check_trained_on(*policy, mdp.problem(), file);
  return policy;
}

}  // namespace

AllocatorKind ppo_kind() {
  return {
      .name = "ppo",
      .summary = "a policy learned by Proximal Policy Optimization from episodes alone, acting greedily",
      .capabilities = {Capability::stationary, Capability::needs_policy, Capability::chains},
      .parameters = {Parameter::path("policy",
                                     "trained policy file (JSON); for several instances, one per instance in order"),
                     Parameter::choice(
                         "policy-check", "digest", {"digest", "shape"},
                         "accept policies trained on this instance only, or any of its size and deadline")},
      .make = [](const Mdp& mdp, const ParameterReader& parameters) -> AllocatorFactory {
        auto policy = policy_for<PpoAllocator>(mdp, parameters, "");
        return [model = &mdp, policy] { return std::make_unique<PpoAllocator>(*model, policy); };
      },
      .commit_rule =
          "its own: the policy, trained acting while planning (train --act concurrent), chooses "
          "each start and step among the useful moves",
      .make_concurrent = [](const ConcurrentMdp& mdp, const ParameterReader& parameters) -> ConcurrentAllocatorFactory {
        auto policy =
            policy_for<ConcurrentPpoAllocator>(mdp, parameters, " acting while planning (train --act concurrent)");
        return [model = &mdp, policy] { return std::make_unique<ConcurrentPpoAllocator>(*model, policy); };
      }};
}

}  // namespace ontime
