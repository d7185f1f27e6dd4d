#include "ontime/ppo_training.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "ontime/error.hpp"
#include "ontime/random.hpp"
#include "ontime/simulator.hpp"
#include "ppo_networks.hpp"

namespace ontime {
namespace {

using Matrix = PolicyNetwork::Matrix;
using Vector = PolicyNetwork::Vector;

// Log-probabilities of a masked softmax over one column of logits.
template <class Column>
void masked_log_softmax(const Column& logits, const std::uint8_t* valid, int count, double* out) {
  double largest = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < count; ++k) {
    if (valid[k] != 0) largest = std::max(largest, static_cast<double>(logits(k)));
  }
  double total = 0;
  for (int k = 0; k < count; ++k) {
    if (valid[k] != 0) total += std::exp(static_cast<double>(logits(k)) - largest);
  }
  const double log_total = largest + std::log(total);
  for (int k = 0; k < count; ++k) {
    out[k] = valid[k] != 0 ? static_cast<double>(logits(k)) - log_total : -std::numeric_limits<double>::infinity();
  }
}

void check(const PpoHyperparameters& h) {
  const bool valid = h.hidden_layers >= 1 && h.hidden_units >= 1 && h.clip > 0 && h.gamma > 0 && h.gamma <= 1 &&
                     h.lambda >= 0 && h.lambda <= 1 && h.actor_learning_rate > 0 && h.critic_learning_rate > 0 &&
                     h.train_iterations >= 1 && h.steps_per_epoch >= 1 && h.max_episode_steps >= 1 && h.target_kl > 0;
  if (!valid) throw UsageError("invalid PPO hyperparameters");
}

// One epoch's experience, one column per step.
struct Batch {
  std::vector<float> features;      // feature_count x steps, column-major
  std::vector<std::uint8_t> valid;  // K x steps
  std::vector<int> actions;
  std::vector<double> log_probabilities;
  std::vector<double> values;
  std::vector<double> rewards;
  std::vector<double> advantages;
  std::vector<double> returns;
  std::size_t steps() const noexcept { return actions.size(); }
  void clear() {
    features.clear();
    valid.clear();
    actions.clear();
    log_probabilities.clear();
    values.clear();
    rewards.clear();
    advantages.clear();
    returns.clear();
  }
};

}  // namespace

template <class Scalar>
double clipped_surrogate_loss(const Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>& logits,
                              const std::vector<std::uint8_t>& valid, const std::vector<int>& actions,
                              const std::vector<double>& old_log_probabilities, const std::vector<double>& advantages,
                              double clip, Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>& gradient,
                              double& approximate_kl) {
  const auto count = static_cast<int>(logits.rows());
  const auto samples = static_cast<std::size_t>(logits.cols());
  gradient.setZero(logits.rows(), logits.cols());
  std::vector<double> log_probabilities(static_cast<std::size_t>(count));
  double loss = 0;
  double kl = 0;
  const double scale = 1.0 / static_cast<double>(samples);
  for (std::size_t n = 0; n < samples; ++n) {
    const auto column = static_cast<Eigen::Index>(n);
    masked_log_softmax(logits.col(column), &valid[n * static_cast<std::size_t>(count)], count,
                       log_probabilities.data());
    const int action = actions[n];
    const double log_probability = log_probabilities[static_cast<std::size_t>(action)];
    const double ratio = std::exp(log_probability - old_log_probabilities[n]);
    const double advantage = advantages[n];
    const double clipped = std::clamp(ratio, 1.0 - clip, 1.0 + clip);
    loss -= scale * std::min(ratio * advantage, clipped * advantage);
    kl += scale * (old_log_probabilities[n] - log_probability);
    // d min(r A, clip(r) A) / d log pi(a): r A while the unclipped term is the minimum (or the
    // ratio is inside the clip range, where both terms agree), zero once clipping holds it.
    const bool inside = ratio >= 1.0 - clip && ratio <= 1.0 + clip;
    const double slope = (inside || ratio * advantage < clipped * advantage) ? ratio * advantage : 0.0;
    if (slope == 0.0) continue;
    for (int k = 0; k < count; ++k) {
      if (valid[n * static_cast<std::size_t>(count) + static_cast<std::size_t>(k)] == 0) continue;
      const double probability = std::exp(log_probabilities[static_cast<std::size_t>(k)]);
      const double d_log_probability = (k == action ? 1.0 : 0.0) - probability;
      gradient(k, column) = static_cast<Scalar>(-scale * slope * d_log_probability);
    }
  }
  approximate_kl = kl;
  return loss;
}

template double clipped_surrogate_loss<float>(const Matrix&, const std::vector<std::uint8_t>&, const std::vector<int>&,
                                              const std::vector<double>&, const std::vector<double>&, double, Matrix&,
                                              double&);
template double clipped_surrogate_loss<double>(const Eigen::MatrixXd&, const std::vector<std::uint8_t>&,
                                               const std::vector<int>&, const std::vector<double>&,
                                               const std::vector<double>&, double, Eigen::MatrixXd&, double&);

PpoTraining train_ppo(const Mdp& mdp, std::uint64_t episodes, std::uint64_t seed, const PpoHyperparameters& h,
                      const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  check(h);
  if (episodes == 0) throw UsageError("training needs at least one episode");
  const auto started = std::chrono::steady_clock::now();
  const int count = mdp.skeleton_count();
  const int inputs = feature_count(count);

  PpoTraining training;
  PpoPolicy& policy = training.policy;
  policy.instance = mdp.problem().name();
  policy.instance_digest = instance_digest(mdp.problem());
  policy.skeleton_count = count;
  policy.deadline = mdp.deadline();
  policy.seed = seed;
  policy.episodes = episodes;
  policy.hyperparameters = h;
  std::vector<int> actor_sizes{inputs};
  std::vector<int> critic_sizes{inputs};
  for (int layer = 0; layer < h.hidden_layers; ++layer) {
    actor_sizes.push_back(h.hidden_units);
    critic_sizes.push_back(h.hidden_units);
  }
  actor_sizes.push_back(count);
  critic_sizes.push_back(1);
  SplitMix64 initialisation(stream_seed(seed, 0));
  PpoNetworks networks{PolicyNetwork(actor_sizes, initialisation), PolicyNetwork(critic_sizes, initialisation)};
  Adam<float> actor_optimiser(networks.actor, h.actor_learning_rate);
  Adam<float> critic_optimiser(networks.critic, h.critic_learning_rate);
  SplitMix64 sampling(stream_seed(seed, 1));
  const std::uint64_t world_seed = stream_seed(seed, 2);

  Batch batch;
  Vector features(inputs);
  std::vector<double> log_probabilities(static_cast<std::size_t>(count));
  std::uint64_t episodes_done = 0;
  std::uint64_t steps_done = 0;
  Matrix inputs_matrix, logits_gradient, value_gradient;

  for (int epoch = 1; episodes_done < episodes; ++epoch) {
    batch.clear();
    std::uint64_t epoch_episodes = 0, epoch_successes = 0;
    while (batch.steps() < static_cast<std::size_t>(h.steps_per_epoch) && episodes_done < episodes) {
      const HiddenWorld world(mdp.problem(), stream_seed(world_seed, episodes_done));
      State state = mdp.start();
      const std::size_t first = batch.steps();
      Status status = Status::running;
      for (int step = 0; step < h.max_episode_steps && status == Status::running; ++step) {
        const ChoiceList choices = mdp.useful_choices(state);
        // No skeleton can succeed any more (the start state of an instance where success is
        // impossible: `apply` reports this as failure only after a step): the episode is lost
        // whatever the learner does, and a step without a choice teaches it nothing.
        if (choices.empty()) {
          status = Status::failure;
          break;
        }
        state_features(mdp, state, features);
        std::uint8_t valid[Problem::kMaxSkeletons] = {};
        for (const int choice : choices) valid[choice] = 1;
        const Vector& logits = networks.actor.evaluate(features);
        masked_log_softmax(logits, valid, count, log_probabilities.data());
        const double value = networks.critic.evaluate(features)(0);
        const auto probability = [&](std::size_t i) {
          return std::exp(log_probabilities[static_cast<std::size_t>(choices[i])]);
        };
        const int action = choices[sample_index(choices.size(), probability, sampling)];
        const int refining = mdp.next_action(state, action);
        const Observation observation = world.observe(refining, state.spent[static_cast<std::size_t>(action)]);
        status = mdp.apply(state, action, observation);

        batch.features.insert(batch.features.end(), features.data(), features.data() + inputs);
        batch.valid.insert(batch.valid.end(), valid, valid + count);
        batch.actions.push_back(action);
        batch.log_probabilities.push_back(log_probabilities[static_cast<std::size_t>(action)]);
        batch.values.push_back(value);
        batch.rewards.push_back(status == Status::success ? 1.0 : 0.0);
      }
      // Advantages (GAE) and discounted returns of the episode; a cut-off episode (step
      // limit) is completed by the critic's value of its last state.
      double next_value = 0;
      if (status == Status::running) {
        state_features(mdp, state, features);
        next_value = networks.critic.evaluate(features)(0);
      }
      const std::size_t last = batch.steps();
      batch.advantages.resize(last);
      batch.returns.resize(last);
      double advantage = 0, discounted = next_value;
      for (std::size_t t = last; t-- > first;) {
        const double delta = batch.rewards[t] + h.gamma * next_value - batch.values[t];
        advantage = delta + h.gamma * h.lambda * advantage;
        discounted = batch.rewards[t] + h.gamma * discounted;
        batch.advantages[t] = advantage;
        batch.returns[t] = discounted;
        next_value = batch.values[t];
      }
      ++episodes_done;
      ++epoch_episodes;
      epoch_successes += status == Status::success ? 1U : 0U;
      steps_done += last - first;
    }

    const std::size_t steps = batch.steps();
    int actor_steps = 0;
    // An epoch of episodes that all ended before their first choice holds nothing to learn from.
    if (steps > 0) {
      double mean = 0, square = 0;
      for (const double a : batch.advantages) mean += a;
      mean /= static_cast<double>(steps);
      for (const double a : batch.advantages) square += (a - mean) * (a - mean);
      const double deviation = std::sqrt(square / static_cast<double>(steps));
      for (double& a : batch.advantages) a = (a - mean) / (deviation + 1e-8);

      inputs_matrix = Eigen::Map<const Matrix>(batch.features.data(), inputs, static_cast<Eigen::Index>(steps));
      for (int iteration = 0; iteration < h.train_iterations; ++iteration) {
        const Matrix& logits = networks.actor.forward(inputs_matrix);
        double kl = 0;
        clipped_surrogate_loss<float>(logits, batch.valid, batch.actions, batch.log_probabilities, batch.advantages,
                                      h.clip, logits_gradient, kl);
        if (kl > 1.5 * h.target_kl) break;
        networks.actor.backward(logits_gradient);
        actor_optimiser.step(networks.actor);
        ++actor_steps;
      }
      for (int iteration = 0; iteration < h.train_iterations; ++iteration) {
        const Matrix& values = networks.critic.forward(inputs_matrix);
        value_gradient.resize(1, static_cast<Eigen::Index>(steps));
        for (std::size_t n = 0; n < steps; ++n) {
          value_gradient(0, static_cast<Eigen::Index>(n)) = static_cast<float>(
              2.0 * (values(0, static_cast<Eigen::Index>(n)) - batch.returns[n]) / static_cast<double>(steps));
        }
        networks.critic.backward(value_gradient);
        critic_optimiser.step(networks.critic);
      }
    }

    LearningCurvePoint point;
    point.epoch = epoch;
    point.episodes = episodes_done;
    point.steps = steps_done;
    point.success_rate = static_cast<double>(epoch_successes) / static_cast<double>(epoch_episodes);
    point.mean_episode_length = static_cast<double>(steps) / static_cast<double>(epoch_episodes);
    point.actor_steps = actor_steps;
    point.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    training.curve.push_back(point);
    if (progress) progress(episodes_done, episodes);
  }
  policy.networks = std::make_shared<const PpoNetworks>(std::move(networks));
  return training;
}

}  // namespace ontime
