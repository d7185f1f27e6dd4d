#include "ontime/allocators/ppo.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "allocators/detail/neural_network.hpp"  // private to the library (src/), as is ppo_networks.hpp
#include "allocators/detail/ppo_networks.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/learn/ppo_training.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/solve/optimal_solver.hpp"
#include "ontime/util/error.hpp"
#include "support/chain_reference.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

using MatrixD = Mlp<double>::Matrix;

double relative_error(double analytic, double numeric) {
  return std::abs(analytic - numeric) / std::max({1e-8, std::abs(analytic), std::abs(numeric)});
}

// Backpropagation against central finite differences of L = sum(W .* output).
TEST(NeuralNetwork, GradientsMatchFiniteDifferences) {
  SplitMix64 generator(17);
  Mlp<double> network({5, 7, 6, 3}, generator);
  MatrixD input = MatrixD::Random(5, 4);
  const MatrixD weights = MatrixD::Random(3, 4);
  const auto loss = [&](Mlp<double>& net) { return net.forward(input).cwiseProduct(weights).sum(); };
  loss(network);
  network.backward(weights);
  const auto analytic_weights = network.weight_gradients();
  const auto analytic_biases = network.bias_gradients();
  constexpr double kStep = 1e-6;
  int checked = 0;
  const auto check = [&](double& parameter, double analytic) {
    const double saved = parameter;
    parameter = saved + kStep;
    const double up = loss(network);
    parameter = saved - kStep;
    const double down = loss(network);
    parameter = saved;
    EXPECT_LT(relative_error(analytic, (up - down) / (2 * kStep)), 1e-6);
    ++checked;
  };
  for (std::size_t layer = 0; layer < network.weights().size(); ++layer) {
    for (Eigen::Index i = 0; i < network.weights()[layer].size(); ++i) {
      check(network.weights()[layer].data()[i], analytic_weights[layer].data()[i]);
    }
    for (Eigen::Index i = 0; i < network.biases()[layer].size(); ++i) {
      check(network.biases()[layer](i), analytic_biases[layer](i));
    }
  }
  EXPECT_EQ(checked, static_cast<int>(network.parameter_count()));
  // The single-sample path agrees with the batch path.
  const Mlp<double>::Vector one = network.evaluate(input.col(2));
  EXPECT_LT((one - network.forward(input).col(2)).norm(), 1e-12);
}

// The clipped surrogate's gradient against finite differences, with masked choices, positive
// and negative advantages, and ratios inside and outside the clip range.
TEST(Ppo, SurrogateGradientMatchesFiniteDifferences) {
  constexpr int kChoices = 4, kSamples = 6;
  SplitMix64 generator(3);
  MatrixD logits(kChoices, kSamples);
  for (Eigen::Index i = 0; i < logits.size(); ++i) logits.data()[i] = 2 * uniform01(generator) - 1;
  std::vector<std::uint8_t> valid{1, 1, 0, 1, 1, 1, 1, 1, 0, 1, 1, 0, 1, 1, 1, 1, 1, 0, 1, 1, 1, 0, 0, 1};
  const std::vector<int> actions{3, 0, 1, 2, 3, 0};
  const std::vector<double> advantages{1.2, -0.7, 0.4, -1.5, 0.9, 2.0};
  // Old log-probabilities chosen so that ratios land inside (1, 4), below (2, 5) and above (0, 3) the range.
  const std::vector<double> old_log{-1.0, -2.5, -0.4, -1.9, -0.2, -3.0};
  MatrixD gradient;
  double kl = 0;
  clipped_surrogate_loss<double>(logits, valid, actions, old_log, advantages, 0.2, gradient, kl);
  int below = 0, inside = 0, above = 0;
  for (int n = 0; n < kSamples; ++n) {
    double total = 0;
    for (int k = 0; k < kChoices; ++k) {
      if (valid[static_cast<std::size_t>(n * kChoices + k)] != 0) total += std::exp(logits(k, n));
    }
    const double ratio = std::exp(logits(actions[static_cast<std::size_t>(n)], n) - std::log(total) -
                                  old_log[static_cast<std::size_t>(n)]);
    below += ratio < 0.8;
    above += ratio > 1.2;
    inside += ratio >= 0.8 && ratio <= 1.2;
  }
  ASSERT_GT(below, 0);
  ASSERT_GT(above, 0);
  ASSERT_GT(inside, 0);
  constexpr double kStep = 1e-6;
  for (Eigen::Index i = 0; i < logits.size(); ++i) {
    MatrixD shifted = logits;
    MatrixD ignored;
    double ignored_kl = 0;
    shifted.data()[i] += kStep;
    const double up =
        clipped_surrogate_loss<double>(shifted, valid, actions, old_log, advantages, 0.2, ignored, ignored_kl);
    shifted.data()[i] -= 2 * kStep;
    const double down =
        clipped_surrogate_loss<double>(shifted, valid, actions, old_log, advantages, 0.2, ignored, ignored_kl);
    EXPECT_NEAR(gradient.data()[i], (up - down) / (2 * kStep), 1e-7) << "entry " << i;
  }
  // Masked choices get no gradient.
  EXPECT_EQ(gradient(2, 0), 0.0);
  EXPECT_EQ(gradient(0, 2), 0.0);
}

TEST(Ppo, LearnsTheBetterSkeletonOfInstanceFour) {
  const Problem problem = testing::paper_instance("instance4");
  const Mdp mdp(problem);
  const auto exact_of = [&mdp](const PpoPolicy& policy) {
    PpoAllocator allocator(mdp, std::make_shared<const PpoPolicy>(policy));
    return evaluate_exactly(mdp, allocator).success_probability;
  };
  // Barely trained, the network prefers a1_1 (0.55); trained, a2_1 (the optimum, 0.9).
  EXPECT_LT(exact_of(train_ppo(mdp, 1, 1).policy), 0.85);
  const PpoTraining training = train_ppo(mdp, 3'000, 1);
  EXPECT_NEAR(exact_of(training.policy), 0.9, 1e-12);
  ASSERT_FALSE(training.curve.empty());
  EXPECT_EQ(training.curve.back().episodes, 3'000U);
  EXPECT_GE(training.curve.front().steps, 4'000U);  // whole episodes until an epoch holds 4,000 steps
}

// Under backtracking (SPEC §7) a trained policy decides in states that hold restore values: its
// exact value is below the optimum and the simulated episodes agree with it.
TEST(Ppo, DecidesUnderBacktracking) {
  const Problem problem = load_problem(testing::source_path("data/instances/backtracking/grasp-and-place.json"));
  ASSERT_TRUE(problem.has_backtracking());
  const Mdp mdp(problem);
  OptimalSolver solver(mdp);
  const double optimum = solver.solve(mdp.start());
  const auto policy = std::make_shared<const PpoPolicy>(train_ppo(mdp, 200, 3).policy);
  PpoAllocator allocator(mdp, policy);
  const double exact = evaluate_exactly(mdp, allocator).success_probability;
  EXPECT_LE(exact, optimum + 1e-12);
  MonteCarloOptions options;
  options.episodes = 4'000;
  options.seed = 5;
  options.threads = 1;
  const double rate = run_monte_carlo(
                          mdp, [&] { return std::make_unique<PpoAllocator>(mdp, policy); }, options)
                          .success_rate;
  EXPECT_NEAR(rate, exact, 4 * std::sqrt(exact * (1 - exact) / static_cast<double>(options.episodes)));
}

// With chains or expiry (SPEC §9) the features go on with each chain's state one-hot and each
// timed slot's static execution / D, after the 1 + 3 K of any instance.
TEST(Ppo, FeaturesOfAStateWithChainsHoldTheChainsOneHotAndTheTimedSlots) {
  const Problem problem = testing::door_open_at_even_steps();
  const Mdp mdp(problem);
  ASSERT_EQ(chain_feature_count(problem), 2 + 1);  // the door's two states, the timed slot of "enter"
  ASSERT_EQ(feature_count(2, chain_feature_count(problem)), 1 + 6 + 3);
  State state = mdp.start();
  ASSERT_EQ(mdp.apply(state, 1, Observation::not_yet().with_chains(1)), Status::running);  // a wait: the door locks
  state.restore[0] = 3;  // (as if 3 steps of execution were ahead of "enter")
  std::vector<float> out(10, -1.0F);
  normalised_state(mdp, state, out);
  const std::vector<float> expected{1.0F / 6, 0, 0, 0, 0, 1.0F / 6, 0, 0, 1, 3.0F / 6};
  EXPECT_EQ(out, expected);
  // Without chains or expiry nothing is added.
  EXPECT_EQ(chain_feature_count(testing::paper_instance("instance1")), 0);
}

// With backtracking too the timed slots follow the culprits' in the state: the features read the
// timed ones only.
TEST(Ppo, FeaturesWithBacktrackingAndChainsReadTheTimedSlots) {
  const Problem problem = testing::door_and_regrasp();
  const Mdp mdp(problem);
  ASSERT_EQ(chain_feature_count(problem), 2 + 1);  // the door's two states, the timed slot of "a"
  State state = mdp.start();
  ASSERT_EQ(mdp.apply(state, 0, Observation::found(2).with_chains(1)), Status::running);
  ASSERT_EQ(mdp.apply(state, 0, Observation::found(2).with_chains(0)), Status::running);
  state.restore[0] = 7;  // (the culprit slot of "a" set apart from its timed slot)
  state.restore[1] = 5;
  std::vector<float> out(7, -1.0F);
  normalised_state(mdp, state, out);
  const std::vector<float> expected{2.0F / 20, 2.0F / 3, 0, 4.0F / 20, 1, 0, 5.0F / 20};
  EXPECT_EQ(out, expected);
}

// The door opens at even steps: entering as soon as the motion is found fails, a step spent
// elsewhere first succeeds. A policy trained there records its chain inputs, reads back, decides
// exactly as the optimum does, and its episodes agree with its exact value; it is refused by an
// instance of the same shape without chains.
TEST(Ppo, LearnsToWaitForTheDoor) {
  const Problem problem = testing::door_open_at_even_steps();
  const Mdp mdp(problem);
  PpoHyperparameters small;
  small.steps_per_epoch = 200;
  PpoAllocator untrained(mdp, std::make_shared<const PpoPolicy>(train_ppo(mdp, 1, 2, small).policy));
  EXPECT_EQ(evaluate_exactly(mdp, untrained).expected_reward, 0.0);  // it enters at once
  const PpoPolicy trained = train_ppo(mdp, 400, 2, small).policy;
  EXPECT_EQ(trained.chain_inputs, 3);
  const auto policy = std::make_shared<const PpoPolicy>(parse_ppo_policy(ppo_policy_to_json(trained), "door-policy"));
  EXPECT_EQ(ppo_policy_to_json(*policy), ppo_policy_to_json(trained));
  PpoAllocator allocator(mdp, policy);
  const ExactEvaluation exact = evaluate_exactly(mdp, allocator);
  EXPECT_EQ(exact.expected_reward, 1.0);
  MonteCarloOptions options;
  options.episodes = 200;
  options.seed = 5;
  const MonteCarloResult episodes = run_monte_carlo(
      mdp, [&] { return std::make_unique<PpoAllocator>(mdp, policy); }, options);
  EXPECT_EQ(episodes.success_rate, 1.0);
  const Problem plain = testing::paper_instance("instance4");  // 2 skeletons, as the door's
  ASSERT_EQ(plain.skeleton_count(), problem.skeleton_count());
  PpoPolicy reshaped = trained;
  reshaped.deadline = plain.deadline();
  const Mdp plain_mdp(plain);
  EXPECT_THROW(PpoAllocator(plain_mdp, std::make_shared<const PpoPolicy>(reshaped)), UsageError);
}

// 60 episodes hold at least two epochs of 200 steps, so that the second update starts from
// weights the first one moved (checked below): the same code as a long run, at a fraction of
// its cost under the sanitizers.
TEST(Ppo, SameSeedSamePolicyByteForByte) {
  const Problem problem = testing::paper_instance("instance2");
  const Mdp mdp(problem);
  PpoHyperparameters small;
  small.steps_per_epoch = 200;
  const PpoTraining first = train_ppo(mdp, 60, 9, small);
  ASSERT_GE(first.curve.size(), 2U);
  EXPECT_GT(first.curve[0].actor_steps, 0);
  const std::string bytes = ppo_policy_to_json(first.policy);
  EXPECT_EQ(bytes, ppo_policy_to_json(train_ppo(mdp, 60, 9, small).policy));
  EXPECT_NE(bytes, ppo_policy_to_json(train_ppo(mdp, 60, 10, small).policy));
}

// Eigen chooses the blocking of its matrix products from the CPU's cache sizes, read at run time;
// training must not depend on them. Each machine below is simulated by the cache sizes Eigen
// would read there (L1d, L2 and L3 per core or shared, as CPUID reports them); the policy's bytes
// must equal those trained under this machine's own sizes. Batches of 2,000 steps: deeper than
// the blocking depth of any of these L1 sizes, so a product split by the caches would show.
TEST(Ppo, SamePolicyBytesWhateverTheCpuCaches) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  PpoHyperparameters h;
  h.steps_per_epoch = 2'000;
  h.train_iterations = 20;
  const std::string here = ppo_policy_to_json(train_ppo(mdp, 1'200, 1, h).policy);
  struct Caches {
    const char* machine;
    std::ptrdiff_t l1, l2, l3;
  };
  const Caches machines[] = {
      {"16 KiB L1d, 256 KiB L2, 2 MiB L3 (a small ARM core)", 16 << 10, 256 << 10, 2 << 20},
      {"32 KiB, 256 KiB, 8 MiB (an older desktop)", 32 << 10, 256 << 10, 8 << 20},
      {"32 KiB, 512 KiB, 16 MiB (Zen 2)", 32 << 10, 512 << 10, 16 << 20},
      {"32 KiB, 1 MiB, 32 MiB (EPYC, Zen 3 and 4)", 32 << 10, 1 << 20, 32 << 20},
      {"48 KiB, 1.25 MiB, 24 MiB (Ice Lake server)", 48 << 10, 1280 << 10, 24 << 20},
      {"64 KiB, 2 MiB, 32 MiB (two cores' totals)", 64 << 10, 2 << 20, 32 << 20},
  };
  const std::ptrdiff_t l1 = Eigen::l1CacheSize(), l2 = Eigen::l2CacheSize(), l3 = Eigen::l3CacheSize();
  for (const Caches& caches : machines) {
    Eigen::setCpuCacheSizes(caches.l1, caches.l2, caches.l3);
    const std::string there = ppo_policy_to_json(train_ppo(mdp, 1'200, 1, h).policy);
    Eigen::setCpuCacheSizes(l1, l2, l3);
    EXPECT_TRUE(there == here) << "another policy under the caches of " << caches.machine;
  }
}

// FNV-1a, 64 bits: a digest of a policy file that is the same on every platform.
std::uint64_t digest(const std::string& bytes) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const char c : bytes) hash = (hash ^ static_cast<unsigned char>(c)) * 0x100000001b3ULL;
  return hash;
}

// The bytes a seed trains are one fact about the trainer, not about the machine or the build:
// this digest was recorded from a Release build on x86-64, and every build the suite runs in
// (Release, the core alone, RelWithDebInfo under the sanitizers, Debug) and every CPU must
// reproduce it. (The digest before it held only on one CPU maker's machines: Adam's square
// roots went through rsqrtps, an approximation whose bits Intel and AMD CPUs differ in.) A deliberate change to the
// trainer changes it, and then Table I's and Table II's ppo cells (README, docs/experiments.md, docs/domains.md) must
// be measured again.
TEST(Ppo, TheSameBytesInEveryBuildAndOnEveryMachine) {
  const Problem problem = testing::paper_instance("instance2");
  const Mdp mdp(problem);
  PpoHyperparameters small;
  small.steps_per_epoch = 500;
  EXPECT_EQ(digest(ppo_policy_to_json(train_ppo(mdp, 300, 9, small).policy)), 0x18b6f2a745a25674ULL);
}

// Instances where success is impossible from the start (every planning PMF "never", deadline 1,
// every execution "never") offer no useful choice: every episode is lost before its first step.
// Training takes no step, writes the untrained policy, and does so the same way every time.
TEST(Ppo, TrainsOnInstancesWhereSuccessIsImpossible) {
  for (const std::string name : {"never_planning", "deadline_one", "never_execution"}) {
    SCOPED_TRACE(name);
    const Problem problem = load_problem(testing::source_path("tests/data/impossible/" + name + ".json"));
    const Mdp mdp(problem);
    ASSERT_TRUE(mdp.useful_choices(mdp.start()).empty());
    const PpoTraining training = train_ppo(mdp, 50, 3);
    ASSERT_EQ(training.curve.size(), 1U);
    EXPECT_EQ(training.curve[0].episodes, 50U);
    EXPECT_EQ(training.curve[0].steps, 0U);
    EXPECT_EQ(training.curve[0].success_rate, 0.0);
    EXPECT_EQ(training.curve[0].actor_steps, 0);
    const std::string policy = ppo_policy_to_json(training.policy);
    EXPECT_EQ(policy, ppo_policy_to_json(train_ppo(mdp, 50, 3).policy));
    PpoAllocator allocator(mdp, std::make_shared<const PpoPolicy>(training.policy));
    EXPECT_EQ(evaluate_exactly(mdp, allocator).success_probability, 0.0);
  }
}

// A policy records the digest of the instance it was trained on; the registry's `ppo` refuses a
// policy of another instance of the same shape, or one without a digest, unless policy-check is
// 'shape'. Labels (name, description) are not part of the digest.
TEST(Ppo, PoliciesAreUsedOnlyOnTheInstanceTheyWereTrainedOn) {
  const Problem problem = testing::paper_instance("instance4");
  const Mdp mdp(problem);
  PpoHyperparameters small;
  small.steps_per_epoch = 200;
  const PpoPolicy policy = train_ppo(mdp, 50, 4, small).policy;
  EXPECT_EQ(policy.instance_digest, instance_digest(problem));
  EXPECT_EQ(policy.instance_digest.size(), 24U);
  EXPECT_EQ(policy.instance_digest.rfind("fnv1a64:", 0), 0U);
  EXPECT_NE(ppo_policy_to_json(policy).find("\"instance_digest\": \"" + policy.instance_digest + "\""),
            std::string::npos);

  std::string text = problem_to_json(problem);
  text.replace(text.find("paper-instance-4"), 16, "renamed-instance");
  const Problem renamed = parse_problem(text, "renamed.json");
  EXPECT_EQ(instance_digest(renamed), policy.instance_digest);
  text.replace(text.find("\"step_seconds\": 1.0"), 19, "\"step_seconds\": 2.0");
  const Problem slower = parse_problem(text, "slower.json");
  ASSERT_EQ(slower.skeleton_count(), problem.skeleton_count());
  ASSERT_EQ(slower.deadline(), problem.deadline());
  EXPECT_NE(instance_digest(slower), policy.instance_digest);
  std::string other_text = problem_to_json(problem);
  other_text.replace(other_text.find("0.3"), 3, "0.2");  // a1_1 plans in one step less often
  const Problem other = parse_problem(other_text, "other.json");
  EXPECT_NE(instance_digest(other), policy.instance_digest);

  const std::filesystem::path file = std::filesystem::temp_directory_path() / "ontime-ppo-test-digest.json";
  save_ppo_policy(policy, file);
  const auto refusal = [&file](const Problem& instance, const std::string& check) {
    const Mdp instance_mdp(instance);
    ParameterValues values{{"policy", file.string()}};
    if (!check.empty()) values.set("policy-check", check);
    try {
      make_allocator_factory("ppo", instance_mdp, values);
    } catch (const UsageError& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refusal(problem, ""), "accepted");
  EXPECT_EQ(refusal(renamed, ""), "accepted");
  for (const Problem* foreign : {&slower, &other}) {
    const std::string message = refusal(*foreign, "");
    EXPECT_NE(message.find("was trained on another instance ('paper-instance-4', " + policy.instance_digest),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("--policy-check shape"), std::string::npos) << message;
    EXPECT_EQ(refusal(*foreign, "shape"), "accepted");
  }
  // A policy written before digests were recorded: refused, saying what to do, unless 'shape'.
  PpoPolicy undigested = policy;
  undigested.instance_digest.clear();
  save_ppo_policy(undigested, file);
  EXPECT_EQ(load_ppo_policy(file).instance_digest, "");
  const std::string message = refusal(problem, "digest");
  EXPECT_NE(message.find("records no digest"), std::string::npos) << message;
  EXPECT_NE(message.find("retrain"), std::string::npos) << message;
  EXPECT_EQ(refusal(problem, "shape"), "accepted");
  std::filesystem::remove(file);
}

TEST(Ppo, PolicyFilesRoundTripAndAreValidated) {
  const Problem problem = testing::paper_instance("instance4");
  const Mdp mdp(problem);
  PpoHyperparameters small;
  small.steps_per_epoch = 200;
  const PpoPolicy policy = train_ppo(mdp, 100, 4, small).policy;
  const std::string text = ppo_policy_to_json(policy);
  const PpoPolicy copy = parse_ppo_policy(text, "policy.json");
  EXPECT_EQ(ppo_policy_to_json(copy), text);
  EXPECT_EQ(copy.hyperparameters.steps_per_epoch, 200);

  const auto place_of = [](const std::string& broken) {
    try {
      parse_ppo_policy(broken, "broken.json");
    } catch (const InputError& error) {
      return error.place();
    }
    return std::string("accepted");
  };
  std::string wrong_format = text;
  wrong_format.replace(wrong_format.find("ontime-ppo-policy"), 17, "something-else-xx");
  EXPECT_EQ(place_of(wrong_format), "format");
  std::string wrong_size = text;
  wrong_size.replace(wrong_size.find("\"skeletons\": 2"), 14, "\"skeletons\": 3");
  EXPECT_EQ(place_of(wrong_size), "actor.sizes");
  EXPECT_EQ(place_of(text.substr(0, text.size() / 2)).rfind("line ", 0), 0U);
  // Unknown keys are refused by name, at every level.
  const auto with_key = [&text](const std::string& after, const std::string& key) {
    std::string changed = text;
    const std::size_t at = changed.find(after);
    changed.insert(at + after.size(), "\"" + key + "\": 1, ");
    return changed;
  };
  EXPECT_EQ(place_of(with_key("{\n", "trained_on")), "trained_on");
  EXPECT_EQ(place_of(with_key("\"hyperparameters\": {", "entropy")), "hyperparameters.entropy");
  EXPECT_EQ(place_of(with_key("\"actor\": {", "activation")), "actor.activation");
  EXPECT_EQ(place_of(with_key("\"critic\": {", "bias")), "critic.bias");
  std::string layer_key = text;
  layer_key.insert(layer_key.find("\"weights\""), "\"dropout\": 0.5, ");
  EXPECT_EQ(place_of(layer_key), "actor.layers[0].dropout");
  std::string bad_digest = text;
  bad_digest.replace(bad_digest.find("fnv1a64:"), 8, "sha256::");
  EXPECT_EQ(place_of(bad_digest), "instance_digest");

  // A policy trained for another instance is refused when used.
  const Problem other = testing::paper_instance("instance1");
  const Mdp other_mdp(other);
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "ontime-ppo-test-policy.json";
  save_ppo_policy(copy, file);
  const ParameterValues options{{"policy", file.string()}};
  EXPECT_THROW(make_allocator_factory("ppo", other_mdp, options), UsageError);
  EXPECT_THROW(make_allocator_factory("ppo", mdp), UsageError);  // no policy at all
  EXPECT_NO_THROW(make_allocator_factory("ppo", mdp, options));
  std::filesystem::remove(file);
  // A policy handle without trained networks is refused, not dereferenced.
  PpoPolicy empty = copy;
  empty.networks.reset();
  EXPECT_THROW(PpoAllocator(mdp, std::make_shared<const PpoPolicy>(empty)), UsageError);
  EXPECT_THROW(ppo_policy_to_json(empty), UsageError);
}

}  // namespace
}  // namespace ontime
