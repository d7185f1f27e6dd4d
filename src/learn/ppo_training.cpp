#include "ontime/learn/ppo_training.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include "allocators/detail/ppo_networks.hpp"
#include "ontime/run/concurrent_session.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
#include "util/portable_math.hpp"

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
    if (valid[k] != 0) total += portable_exp(static_cast<double>(logits(k)) - largest);
  }
  const double log_total = largest + portable_log(total);
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
    const double ratio = portable_exp(log_probability - old_log_probabilities[n]);
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
      const double probability = portable_exp(log_probabilities[static_cast<std::size_t>(k)]);
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

namespace {

// The episodes a trainer plays plan-first (SPEC §2): a Session whose outputs are the skeletons.
class PlanFirstEpisodes {
 public:
  explicit PlanFirstEpisodes(const Mdp& mdp)
      : mdp_(mdp),
        world_(mdp.problem(), 0),
        inputs_(feature_count(mdp.skeleton_count(), chain_feature_count(mdp.problem()))) {
    choices_.reserve(static_cast<std::size_t>(mdp.skeleton_count()));
  }
  int inputs() const noexcept { return inputs_; }
  int outputs() const noexcept { return mdp_.skeleton_count(); }
  void begin(std::uint64_t world_seed) {
    world_.begin_episode(world_seed);
    session_.emplace(mdp_, world_seed);  // (its simulated chains, SPEC §9)
  }
  // The outputs the learner may choose now: the useful choices.
  const std::vector<int>& choices() {
    const ChoiceList useful = mdp_.useful_choices(session_->state());
    choices_.assign(useful.begin(), useful.end());
    return choices_;
  }
  void features(Vector& out) const { state_features(mdp_, session_->state(), out); }
  Status act(int output) {
    session_->decide(output);
    return session_->carry_out(world_);
  }
  double reward() const noexcept { return session_->reward(); }

 private:
  const Mdp& mdp_;
  HiddenWorld world_;  // redrawn for every episode
  int inputs_;
  std::optional<Session> session_;
  std::vector<int> choices_;
};

// The episodes a trainer plays acting while planning (SPEC §10): a ConcurrentSession whose outputs
// are the moves (ppo_move_output). At a certain success the complete plan runs by itself, as
// ConcurrentPpoAllocator runs it: no decision is left to learn there.
class ConcurrentEpisodes {
 public:
  explicit ConcurrentEpisodes(const ConcurrentMdp& mdp)
      : mdp_(mdp),
        world_(mdp.problem(), 0),
        inputs_(concurrent_feature_count(mdp.skeleton_count(), concurrent_chain_feature_count(mdp.problem()))) {}
  int inputs() const noexcept { return inputs_; }
  int outputs() const noexcept { return concurrent_move_count(mdp_.skeleton_count()); }
  void begin(std::uint64_t world_seed) {
    world_.begin_episode(world_seed);
    session_.emplace(mdp_, world_seed);  // (its simulated chains, SPEC §9)
    settle();
  }
  // The outputs of the useful moves (ConcurrentMdp::useful_moves), in the solver's order.
  const std::vector<int>& choices() {
    moves_ = mdp_.useful_moves(session_->state());
    choices_.clear();
    for (const ConcurrentMdp::Move& move : moves_) choices_.push_back(ppo_move_output(mdp_, session_->state(), move));
    return choices_;
  }
  void features(Vector& out) const { concurrent_state_features(mdp_, session_->state(), out); }
  Status act(int output) {
    const auto chosen = std::find(choices_.begin(), choices_.end(), output) - choices_.begin();
    carry_out(moves_[static_cast<std::size_t>(chosen)]);
    settle();
    return session_->status();
  }
  double reward() const noexcept { return session_->reward(); }

 private:
  void carry_out(const ConcurrentMdp::Move& move) {
    if (!session_->decide(move).is_start() && session_->status() == Status::running) session_->carry_out(world_);
  }
  // Runs a complete plan that is sure to succeed.
  void settle() {
    while (session_->status() == Status::running && mdp_.certain_success(session_->state())) {
      carry_out(mdp_.run_complete_plan(session_->state()));
    }
  }

  const ConcurrentMdp& mdp_;
  HiddenWorld world_;  // redrawn for every episode
  int inputs_;
  std::optional<ConcurrentSession> session_;
  std::vector<ConcurrentMdp::Move> moves_;
  std::vector<int> choices_;
};

// One training run: the networks, their optimisers, the sampling stream and the scratch buffers
// that every episode and update reuse, over the episodes of one acting mode (PlanFirstEpisodes,
// ConcurrentEpisodes). train_ppo alternates play_episode (until an epoch's steps are collected)
// and update.
template <class Episodes>
class PpoTrainer {
 public:
  template <class Model>
  PpoTrainer(const Model& mdp, std::uint64_t seed, const PpoHyperparameters& h)
      : episodes_(mdp),
        h_(h),
        count_(episodes_.outputs()),
        inputs_(episodes_.inputs()),
        networks_(initial_networks(stream_seed(seed, 0))),
        actor_optimiser_(networks_.actor, h.actor_learning_rate),
        critic_optimiser_(networks_.critic, h.critic_learning_rate),
        sampling_(stream_seed(seed, 1)),
        features_(inputs_),
        log_probabilities_(static_cast<std::size_t>(count_)),
        valid_(static_cast<std::size_t>(count_)) {}

  Batch& batch() noexcept { return batch_; }
  PpoNetworks take_networks() { return std::move(networks_); }

  // Plays one episode in the hidden world of `world_seed` with the current actor (choices
  // sampled), appends its steps to the batch with their advantages (GAE) and returns, and
  // returns how it ended. The episode steps through a session (session.hpp,
  // concurrent_session.hpp) with the actor's choices, as the episode runner's allocators step
  // through theirs.
  Status play_episode(std::uint64_t world_seed) {
    episodes_.begin(world_seed);
    const std::size_t first = batch_.steps();
    Status status = Status::running;
    for (int step = 0; step < h_.max_episode_steps && status == Status::running; ++step) {
      const std::vector<int>& choices = episodes_.choices();
      // No skeleton can succeed any more (the start state of an instance where success is
      // impossible: `apply` reports this as failure only after a step): the episode is lost
      // whatever the learner does, and a step without a choice teaches it nothing.
      if (choices.empty()) {
        status = Status::failure;
        break;
      }
      episodes_.features(features_);
      std::fill(valid_.begin(), valid_.end(), std::uint8_t{0});
      for (const int choice : choices) valid_[choice] = 1;
      const std::uint8_t* valid = valid_.data();
      const Vector& logits = networks_.actor.evaluate(features_);
      masked_log_softmax(logits, valid, count_, log_probabilities_.data());
      const double value = networks_.critic.evaluate(features_)(0);
      const auto probability = [&](std::size_t i) {
        return portable_exp(log_probabilities_[static_cast<std::size_t>(choices[i])]);
      };
      const int action = choices[sample_index(choices.size(), probability, sampling_)];
      status = episodes_.act(action);

      batch_.features.insert(batch_.features.end(), features_.data(), features_.data() + inputs_);
      batch_.valid.insert(batch_.valid.end(), valid, valid + count_);
      batch_.actions.push_back(action);
      batch_.log_probabilities.push_back(log_probabilities_[static_cast<std::size_t>(action)]);
      batch_.values.push_back(value);
      batch_.rewards.push_back(episodes_.reward());
    }
    // Advantages (GAE) and discounted returns of the episode; a cut-off episode (step
    // limit) is completed by the critic's value of its last state.
    double next_value = 0;
    if (status == Status::running) {
      episodes_.features(features_);
      next_value = networks_.critic.evaluate(features_)(0);
    }
    const std::size_t last = batch_.steps();
    batch_.advantages.resize(last);
    batch_.returns.resize(last);
    double advantage = 0, discounted = next_value;
    for (std::size_t t = last; t-- > first;) {
      const double delta = batch_.rewards[t] + h_.gamma * next_value - batch_.values[t];
      advantage = delta + h_.gamma * h_.lambda * advantage;
      discounted = batch_.rewards[t] + h_.gamma * discounted;
      batch_.advantages[t] = advantage;
      batch_.returns[t] = discounted;
      next_value = batch_.values[t];
    }
    return status;
  }

  // One PPO update from the batch: normalised advantages, clipped-surrogate actor steps (until
  // the KL limit) and critic steps. Returns the actor steps taken; an empty batch (episodes that
  // all ended before their first choice) holds nothing to learn from.
  int update() {
    const std::size_t steps = batch_.steps();
    if (steps == 0) return 0;
    double mean = 0, square = 0;
    for (const double a : batch_.advantages) mean += a;
    mean /= static_cast<double>(steps);
    for (const double a : batch_.advantages) square += (a - mean) * (a - mean);
    const double deviation = std::sqrt(square / static_cast<double>(steps));
    for (double& a : batch_.advantages) a = (a - mean) / (deviation + 1e-8);

    int actor_steps = 0;
    inputs_matrix_ = Eigen::Map<const Matrix>(batch_.features.data(), inputs_, static_cast<Eigen::Index>(steps));
    for (int iteration = 0; iteration < h_.train_iterations; ++iteration) {
      const Matrix& logits = networks_.actor.forward(inputs_matrix_);
      double kl = 0;
      clipped_surrogate_loss<float>(logits, batch_.valid, batch_.actions, batch_.log_probabilities, batch_.advantages,
                                    h_.clip, logits_gradient_, kl);
      if (kl > 1.5 * h_.target_kl) break;
      networks_.actor.backward(logits_gradient_);
      actor_optimiser_.step(networks_.actor);
      ++actor_steps;
    }
    for (int iteration = 0; iteration < h_.train_iterations; ++iteration) {
      const Matrix& values = networks_.critic.forward(inputs_matrix_);
      value_gradient_.resize(1, static_cast<Eigen::Index>(steps));
      for (std::size_t n = 0; n < steps; ++n) {
        value_gradient_(0, static_cast<Eigen::Index>(n)) = static_cast<float>(
            2.0 * (values(0, static_cast<Eigen::Index>(n)) - batch_.returns[n]) / static_cast<double>(steps));
      }
      networks_.critic.backward(value_gradient_);
      critic_optimiser_.step(networks_.critic);
    }
    return actor_steps;
  }

 private:
  PpoNetworks initial_networks(std::uint64_t seed) const {
    std::vector<int> actor_sizes{inputs_};
    std::vector<int> critic_sizes{inputs_};
    for (int layer = 0; layer < h_.hidden_layers; ++layer) {
      actor_sizes.push_back(h_.hidden_units);
      critic_sizes.push_back(h_.hidden_units);
    }
    actor_sizes.push_back(count_);
    critic_sizes.push_back(1);
    SplitMix64 initialisation(seed);
    // Sequenced: the actor draws its weights first, then the critic, from one stream.
    PolicyNetwork actor(actor_sizes, initialisation);
    PolicyNetwork critic(critic_sizes, initialisation);
    return PpoNetworks{std::move(actor), std::move(critic)};
  }

  Episodes episodes_;
  const PpoHyperparameters& h_;
  int count_;  // the actor's outputs
  int inputs_;
  PpoNetworks networks_;
  Adam<float> actor_optimiser_;
  Adam<float> critic_optimiser_;
  SplitMix64 sampling_;
  Batch batch_;
  Vector features_;
  std::vector<double> log_probabilities_;
  std::vector<std::uint8_t> valid_;  // 1 for the outputs of the useful choices of the current state
  Matrix inputs_matrix_, logits_gradient_, value_gradient_;
};

}  // namespace

namespace {

// Trains on `episodes` episodes of one acting mode; `policy` already says what it is trained for.
template <class Episodes, class Model>
PpoTraining train(const Model& mdp, PpoPolicy policy, std::uint64_t episodes, std::uint64_t seed,
                  const PpoHyperparameters& h, const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  check(h);
  if (episodes == 0) throw UsageError("training needs at least one episode");
  const auto started = std::chrono::steady_clock::now();

  PpoTraining training;
  training.policy = std::move(policy);
  training.policy.seed = seed;
  training.policy.episodes = episodes;
  training.policy.hyperparameters = h;
  PpoTrainer<Episodes> trainer(mdp, seed, h);
  const std::uint64_t world_seed = stream_seed(seed, 2);

  std::uint64_t episodes_done = 0;
  std::uint64_t steps_done = 0;
  for (int epoch = 1; episodes_done < episodes; ++epoch) {
    trainer.batch().clear();
    std::uint64_t epoch_episodes = 0, epoch_successes = 0;
    while (trainer.batch().steps() < static_cast<std::size_t>(h.steps_per_epoch) && episodes_done < episodes) {
      const std::size_t before = trainer.batch().steps();
      const Status status = trainer.play_episode(stream_seed(world_seed, episodes_done));
      ++episodes_done;
      ++epoch_episodes;
      epoch_successes += status == Status::success ? 1U : 0U;
      steps_done += trainer.batch().steps() - before;
    }
    const std::size_t steps = trainer.batch().steps();
    const int actor_steps = trainer.update();

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
  training.policy.networks = std::make_shared<const PpoNetworks>(trainer.take_networks());
  return training;
}

}  // namespace

namespace {

// What a policy of `mdp` records of its instance before training.
template <class Model>
PpoPolicy untrained_policy(const Model& mdp, Acting acting, int chain_inputs) {
  PpoPolicy policy;
  policy.acting = acting;
  policy.instance = mdp.problem().name();
  policy.instance_digest = instance_digest(mdp.problem());
  policy.skeleton_count = mdp.skeleton_count();
  policy.chain_inputs = chain_inputs;
  policy.deadline = mdp.deadline();
  return policy;
}

}  // namespace

PpoTraining train_ppo(const Mdp& mdp, std::uint64_t episodes, std::uint64_t seed, const PpoHyperparameters& h,
                      const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  return train<PlanFirstEpisodes>(mdp, untrained_policy(mdp, Acting::plan_first, chain_feature_count(mdp.problem())),
                                  episodes, seed, h, progress);
}

PpoTraining train_ppo(const ConcurrentMdp& mdp, std::uint64_t episodes, std::uint64_t seed, const PpoHyperparameters& h,
                      const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  return train<ConcurrentEpisodes>(
      mdp, untrained_policy(mdp, Acting::concurrent, concurrent_chain_feature_count(mdp.problem())), episodes, seed, h,
      progress);
}

}  // namespace ontime
