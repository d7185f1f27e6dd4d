#pragma once
// Internal: the Eigen side of the `ppo` allocator. The actor and critic networks a PpoPolicy
// holds, the features a state is given to them as, and the clipped surrogate loss of training.
// Kept out of the installed headers so that Eigen stays private to the library: a PpoPolicy is
// an opaque handle outside it (ontime/allocators/ppo.hpp).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "allocators/detail/neural_network.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/mdp/state.hpp"

namespace ontime {

using PolicyNetwork = Mlp<float>;

// The trained networks of a PpoPolicy: the actor's outputs are preferences over the skeletons
// (acting while planning: over the moves, ppo_move_output),
// the critic's single output estimates the state's value.
struct PpoNetworks {
  PolicyNetwork actor;
  PolicyNetwork critic;
};

// The features of a state (normalised_state, ontime/allocators/ppo.hpp) in a network's input.
void state_features(const Mdp& mdp, const State& state, PolicyNetwork::Vector& features);
// The same acting while planning (concurrent_normalised_state).
void concurrent_state_features(const ConcurrentMdp& mdp, const ConcurrentState& state, PolicyNetwork::Vector& features);

// The clipped surrogate loss of PPO, -mean(min(r A, clip(r, 1 - e, 1 + e) A)) with
// r = exp(log pi(a | s) - old log pi), over a batch of logits (one column per sample) with
// invalid choices masked (valid[k + K n] != 0). Writes dLoss/dlogits (same shape) and the
// approximate KL mean(old log pi - log pi). Declared here for its gradient test.
template <class Scalar>
double clipped_surrogate_loss(const Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>& logits,
                              const std::vector<std::uint8_t>& valid, const std::vector<int>& actions,
                              const std::vector<double>& old_log_probabilities, const std::vector<double>& advantages,
                              double clip, Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>& gradient,
                              double& approximate_kl);

}  // namespace ontime
