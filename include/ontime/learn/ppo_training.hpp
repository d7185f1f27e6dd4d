#pragma once
// Training the `ppo` allocator by Proximal Policy Optimization (Schulman et al. 2017) on
// simulated episodes, with the paper's Appendix B settings (PpoHyperparameters defaults):
// actor and critic of three tanh hidden layers of 64 units, clip 0.2, gamma 0.99, actor
// learning rate 3e-4, critic 1e-3, 80 gradient steps per update, 4,000 steps per epoch, at
// most 1,000 steps per episode; GAE(lambda = 0.97) advantages, normalised per epoch; actor steps
// stop early once the approximate KL passes 1.5 x 0.01 (as in Spinning Up).
//
// The learner sees only states, its masked choices and the 0/1 reward at the end of an episode;
// the distributions serve only to simulate the hidden worlds. An epoch collects whole episodes
// until it holds at least `steps_per_epoch` steps. Same seed, same policy, bit for bit.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "ontime/allocators/ppo.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/util/output_set.hpp"

namespace ontime {

struct LearningCurvePoint {
  int epoch = 0;
  std::uint64_t episodes = 0;      // training episodes so far
  std::uint64_t steps = 0;         // environment steps so far
  double success_rate = 0;         // of this epoch's episodes (sampled actions)
  double mean_episode_length = 0;  // steps
  int actor_steps = 0;             // gradient steps before the KL stop
  double seconds = 0;              // wall-clock since training started
};

struct PpoTraining {
  PpoPolicy policy;
  std::vector<LearningCurvePoint> curve;
};

// Trains on `episodes` simulated episodes. Throws UsageError for invalid hyperparameters.
PpoTraining train_ppo(const Mdp& mdp, std::uint64_t episodes, std::uint64_t seed,
                      const PpoHyperparameters& hyperparameters = {},
                      const std::function<void(std::uint64_t done, std::uint64_t total)>& progress = {});
// The same acting while planning (SPEC §10): episodes of ConcurrentSession, the actor's outputs
// the moves (ppo_move_output) masked to the useful ones, a complete plan sure to succeed run by
// itself (as ConcurrentPpoAllocator runs it, so no decision is recorded there). The policy says
// Acting::concurrent and drives ConcurrentPpoAllocator. Same seed, same policy, bit for bit.
PpoTraining train_ppo(const ConcurrentMdp& mdp, std::uint64_t episodes, std::uint64_t seed,
                      const PpoHyperparameters& hyperparameters = {},
                      const std::function<void(std::uint64_t done, std::uint64_t total)>& progress = {});

// The learning curve as CSV: one row per epoch (epoch, episodes, steps, success_rate,
// mean_episode_length, actor_steps, seconds).
std::string learning_curve_csv(const std::vector<LearningCurvePoint>& curve);

// Where the learning curve of a policy file goes: POLICY with the extension .curve.csv (and its
// plot .curve.png).
std::filesystem::path learning_curve_path(const std::filesystem::path& policy, const char* extension = ".curve.csv");

// Stages a training's files in `files` (util/output_set.hpp: all renamed together at commit, so
// an interruption leaves the previous set or this one): the policy at `policy` and its learning
// curve beside it. Returns where the curve CSV is staged (a plot drawn from it goes in the same
// set). `ontime train` and Python's ontime.train_ppo write through this.
std::filesystem::path stage_ppo_training(OutputSet& files, const PpoTraining& training,
                                         const std::filesystem::path& policy);

}  // namespace ontime
