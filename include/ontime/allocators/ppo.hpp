#pragma once
// `ppo`: a model-free policy learned by Proximal Policy Optimization (SPEC §3, paper §VI and
// Appendix B), trained by `train_ppo` (ontime/ppo_training.hpp) from episodes alone, without
// the distributions.
//
// Computes, before every step, the actor network's preferences over the useful choices of the
// state (the others are masked out) and takes the most preferred (ties: lowest index). Acting
// greedily makes the trained policy a function of the state, so its exact success probability
// can be computed (SPEC §4).
// Features of a state (the MDP state of SPEC §2 normalised): CT / D, and per skeleton
// l_k / A_k, PT_k / D and ET_k / D.
// No guarantee: as good as the training made it. Cost per decision: one forward pass of a
// 3 x 64 tanh network (a few microseconds), no allocation.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "ontime/allocators/allocator.hpp"
#include "ontime/mdp/mdp.hpp"

namespace ontime {

struct PpoHyperparameters {
  int hidden_layers = 3;
  int hidden_units = 64;
  double clip = 0.2;
  double gamma = 0.99;
  double lambda = 0.97;  // GAE
  double actor_learning_rate = 3e-4;
  double critic_learning_rate = 1e-3;
  int train_iterations = 80;  // gradient steps per update, actor and critic each
  int steps_per_epoch = 4'000;
  int max_episode_steps = 1'000;
  double target_kl = 0.01;  // actor steps stop early past 1.5 x this KL
};

// The number of features of a state with K skeletons: 1 + 3 K, and `chain_inputs` more with
// chains or expiry (chain_feature_count).
int feature_count(int skeleton_count, int chain_inputs = 0) noexcept;
// The features beyond 1 + 3 K that a problem with chains or expiry (SPEC §9) adds: one per
// state of each chain, then one per timed slot; 0 for any other problem.
int chain_feature_count(const Problem& problem) noexcept;
// The features of a state, written to `out` (size feature_count(K, chain_feature_count)): CT / D,
// then per skeleton l_k / A_k, PT_k / D and ET_k / D (ET_k saturates at D + 1, so its feature at
// (D + 1) / D); with chains or expiry, then each chain's state one-hot (1 at its state, 0 at
// its others), then each timed slot's static execution before its action / D. The input of the
// policy networks, and the observation of the Python environment.
void normalised_state(const Mdp& mdp, const State& state, std::span<float> out) noexcept;

// The actor and critic networks; defined inside the library (they are Eigen matrices, which
// stay private to it), so that a policy is an opaque handle here.
struct PpoNetworks;

// A trained actor and critic, and what they were trained for. Made by `train_ppo` or
// `load_ppo_policy`; copies share the (immutable) networks.
struct PpoPolicy {
  std::string instance;         // name of the instance it was trained on
  std::string instance_digest;  // instance_digest() of it; empty in files written before digests
  int skeleton_count = 0;
  int chain_inputs = 0;  // chain_feature_count of the instance (with chains or expiry; else 0)
  Steps deadline = 0;
  std::uint64_t seed = 0;
  std::uint64_t episodes = 0;  // training episodes
  PpoHyperparameters hyperparameters;
  std::shared_ptr<const PpoNetworks> networks;
};

// What a policy records of the instance it was trained on: FNV-1a (64 bits) of the instance's
// canonical JSON (problem_to_json) without its labels (name, description), written
// "fnv1a64:" and 16 hexadecimal digits. The same content gives the same digest whatever the
// file's layout, key order or name; any change of deadline, step length, distribution or
// skeleton gives another.
std::string instance_digest(const Problem& problem);

// Policy files (JSON). Saving is atomic; loading validates every field and raises InputError
// naming the file, the JSON path and the rule (an unknown key is refused by name). Writing a
// policy without networks is a UsageError.
void save_ppo_policy(const PpoPolicy& policy, const std::filesystem::path& path);
std::string ppo_policy_to_json(const PpoPolicy& policy);
PpoPolicy load_ppo_policy(const std::filesystem::path& path);
PpoPolicy parse_ppo_policy(std::string_view text, std::string_view source);

class PpoAllocator final : public Allocator {
 public:
  // Throws UsageError when the policy holds no networks or was trained for another number of
  // skeletons or deadline.
  PpoAllocator(const Mdp& mdp, std::shared_ptr<const PpoPolicy> policy);
  ~PpoAllocator() override;
  PpoAllocator(const PpoAllocator&) = delete;
  PpoAllocator& operator=(const PpoAllocator&) = delete;

  std::string_view name() const noexcept override { return "ppo"; }
  int choose(const State& state) override;

 private:
  struct Evaluation;  // own copy of the actor (evaluation uses per-network scratch buffers), features

  const Mdp* mdp_;
  std::shared_ptr<const PpoPolicy> policy_;
  std::unique_ptr<Evaluation> evaluation_;
};

}  // namespace ontime
