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
//
// Acting while planning (SPEC §10), a policy trained in that mode (PpoPolicy::acting) drives a
// ConcurrentPpoAllocator: the actor has 2 K + 1 outputs, one move each (ppo_move_output), and
// chooses among the state's useful moves (ConcurrentMdp::useful_moves, the others masked out)
// what to refine and when the robot starts; its own commit rule. Features of a concurrent state:
// concurrent_normalised_state.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
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

// Acting while planning (SPEC §10). The number of features of a concurrent state with K skeletons:
// 2 + 6 K, and `chain_inputs` more with chains or expiry (concurrent_chain_feature_count).
int concurrent_feature_count(int skeleton_count, int chain_inputs = 0) noexcept;
// The features beyond 2 + 6 K that a problem with chains or expiry adds acting while planning: one
// per state of each chain; 0 for any other problem. (The timed slots of the plan-first features
// have no counterpart: a concurrent state holds the robot's backlog itself.)
int concurrent_chain_feature_count(const Problem& problem) noexcept;
// The features of a concurrent state, written to `out` (size concurrent_feature_count(K,
// concurrent_chain_feature_count)): CT / D, r / D; then per skeleton, 0 for each when it is
// dropped, else 1, its actions started / length, l_k / length, PT_k / D, the robot's backlog
// (ConcurrentMdp::robot_free less CT, at most D + 1) / D, and 1 when its next action to execute may
// start now (ConcurrentMdp::startable), else 0; with chains or expiry, then each chain's state
// one-hot. O(K * A_max), no allocation but the startable list.
void concurrent_normalised_state(const ConcurrentMdp& mdp, const ConcurrentState& state, std::span<float> out);
// The actor's outputs acting while planning: 2 K + 1.
int concurrent_move_count(int skeleton_count) noexcept;
// The output that stands for `move` in `state`: k < K a step refining skeleton k's next action
// (its group's lowest index, as ConcurrentMdp::refine_choices names it), K + k the start of
// skeleton k's next action to execute (the lowest live k whose next action is the one started), 2 K
// a step in which the planner idles. -1 for a start of an action no live skeleton executes next.
int ppo_move_output(const ConcurrentMdp& mdp, const ConcurrentState& state, const ConcurrentMdp::Move& move) noexcept;

// The actor and critic networks; defined inside the library (they are Eigen matrices, which
// stay private to it), so that a policy is an opaque handle here.
struct PpoNetworks;

// A trained actor and critic, and what they were trained for. Made by `train_ppo` or
// `load_ppo_policy`; copies share the (immutable) networks.
struct PpoPolicy {
  // The mode it was trained in (SPEC §10): plan-first policies drive PpoAllocator, concurrent ones
  // ConcurrentPpoAllocator; the networks' sizes follow (feature_count or concurrent_feature_count
  // inputs; K or concurrent_move_count outputs).
  Acting acting = Acting::plan_first;
  std::string instance;         // name of the instance it was trained on
  std::string instance_digest;  // instance_digest() of it; empty in files written before digests
  int skeleton_count = 0;
  int chain_inputs = 0;  // (concurrent_)chain_feature_count of the instance (with chains or expiry; else 0)
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
  // Throws UsageError when the policy holds no networks, was trained acting while planning or for
  // another number of skeletons or deadline.
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

// The trained policy acting while planning: its own commit rule. At a certain success
// (ConcurrentMdp::certain_success) it runs the complete plan (optimal there); otherwise the actor's
// most preferred output among the state's useful moves (ties: lowest output). Stationary, so that
// ConcurrentSolver's policy mode values it exactly. Cost per move: the useful moves, the startable
// list and one forward pass.
class ConcurrentPpoAllocator final : public ConcurrentAllocator {
 public:
  // Throws UsageError when the policy holds no networks, was trained plan-first or for another
  // number of skeletons, deadline or chain inputs. `mdp` must outlive this object.
  ConcurrentPpoAllocator(const ConcurrentMdp& mdp, std::shared_ptr<const PpoPolicy> policy);
  ~ConcurrentPpoAllocator() override;
  ConcurrentPpoAllocator(const ConcurrentPpoAllocator&) = delete;
  ConcurrentPpoAllocator& operator=(const ConcurrentPpoAllocator&) = delete;

  std::string_view name() const noexcept override { return "ppo"; }
  ConcurrentMdp::Move choose(const ConcurrentState& state) override;

 private:
  struct Evaluation;

  const ConcurrentMdp* mdp_;
  std::shared_ptr<const PpoPolicy> policy_;
  std::unique_ptr<Evaluation> evaluation_;
};

}  // namespace ontime
