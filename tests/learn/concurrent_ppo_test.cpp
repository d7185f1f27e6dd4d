// The `ppo` allocator acting while planning (SPEC §10): its features of a concurrent state, its
// outputs for the moves, training in the mode, its policy files and its place in the registry.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <set>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/allocators/ppo.hpp"
#include "ontime/learn/ppo_training.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/util/error.hpp"
#include "support/chain_reference.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

std::string message_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const UsageError& error) {
    return error.what();
  }
  return "(no UsageError)";
}

double concurrent_optimum(const ConcurrentMdp& mdp) {
  ConcurrentSolver solver(mdp);
  return solver.solve(mdp.start());
}

double exact_of(const ConcurrentMdp& mdp, const PpoPolicy& policy) {
  ConcurrentPpoAllocator allocator(mdp, std::make_shared<const PpoPolicy>(policy));
  return evaluate_exactly(mdp, allocator).success_probability;
}

PpoHyperparameters small_epochs() {
  PpoHyperparameters small;
  small.steps_per_epoch = 200;
  return small;
}

// Instance 1 (D = 14): skeletons 1, 2 and 3 share a2_1, and 1 and 2 share a2_2 below it.
TEST(ConcurrentPpo, FeaturesOfAStateByHand) {
  const ConcurrentMdp mdp(testing::paper_instance("instance1"));
  ASSERT_EQ(mdp.deadline(), 14);
  ASSERT_EQ(concurrent_feature_count(4), 2 + 24);
  ASSERT_EQ(concurrent_chain_feature_count(mdp.problem()), 0);
  std::vector<float> out(26, -1.0F);
  // a2_1 found in the first step, 3 steps of execution; the robot is idle at CT = 1.
  const ConcurrentState found = mdp.step(mdp.start(), 1, Observation::found(3));
  concurrent_normalised_state(mdp, found, out);
  const float d = 14;
  std::vector<float> expected{1 / d, 0,                          // CT, r
                              1,     0, 0,        0, 0,     0,   // skeleton 0: nothing of a1_1 yet
                              1,     0, 1.0F / 3, 0, 3 / d, 1,   // 1: a2_1 refined, may start
                              1,     0, 1.0F / 3, 0, 3 / d, 1,   // 2: the same
                              1,     0, 1.0F / 3, 0, 3 / d, 1};  // 3: the same
  EXPECT_EQ(out, expected);
  // The robot starts a2_1: skeleton 0 is dropped, the others have one action started, the robot
  // 3 steps left, which is their backlog, and nothing may start while it executes.
  const int a2_1 = mdp.problem().action_at(1, 0);
  const ConcurrentMdp::StartOutcome started = mdp.start_action(found, a2_1);
  ASSERT_FALSE(started.ends);
  concurrent_normalised_state(mdp, started.next, out);
  expected = {1 / d, 3 / d,                            //
              0,     0,        0,        0, 0,     0,  //
              1,     1.0F / 3, 1.0F / 3, 0, 3 / d, 0,  //
              1,     1.0F / 3, 1.0F / 3, 0, 3 / d, 0,  //
              1,     1.0F / 3, 1.0F / 3, 0, 3 / d, 0};
  EXPECT_EQ(out, expected);
}

TEST(ConcurrentPpo, EveryUsefulMoveHasItsOwnOutput) {
  const ConcurrentMdp mdp(testing::paper_instance("instance1"));
  const ConcurrentState found = mdp.step(mdp.start(), 1, Observation::found(3));
  const int a2_1 = mdp.problem().action_at(1, 0);
  // A start of a2_1 is skeleton 1's output (the lowest through it), after the K step outputs.
  EXPECT_EQ(ppo_move_output(mdp, found, {a2_1, ConcurrentMdp::kWait}), 4 + 1);
  EXPECT_EQ(ppo_move_output(mdp, found, {-1, 3}), 3);
  EXPECT_EQ(ppo_move_output(mdp, found, {}), 8);  // the planner idles
  EXPECT_EQ(concurrent_move_count(4), 9);
  // On random states of random instances (with backtracking and chains too) the useful moves'
  // outputs are distinct and in range.
  int checked = 0;
  const int instances = testing::repetitions_to_check(60);
  for (std::uint64_t seed = 0; seed < static_cast<std::uint64_t>(instances); ++seed) {
    Problem problem = testing::random_instance(seed + 900, 4, 3, 10);
    if (seed % 3 == 1) problem = testing::with_backtracking(problem, seed);
    if (seed % 3 == 2) problem = testing::with_random_chains(problem, seed, false);
    const ConcurrentMdp random(problem);
    SplitMix64 generator(seed);
    ConcurrentState state = random.start();
    while (true) {
      const std::vector<ConcurrentMdp::Move> moves = random.useful_moves(state);
      if (moves.empty()) break;
      std::set<int> outputs;
      for (const ConcurrentMdp::Move& move : moves) {
        const int output = ppo_move_output(random, state, move);
        EXPECT_GE(output, 0);
        EXPECT_LT(output, concurrent_move_count(random.skeleton_count()));
        outputs.insert(output);
      }
      EXPECT_EQ(outputs.size(), moves.size()) << "seed " << seed;
      ++checked;
      // One random outcome of a random move.
      const ConcurrentMdp::Move move = moves[generator() % moves.size()];
      std::vector<ConcurrentState> next;
      bool ended = false;
      if (move.is_start()) {
        random.for_each_start_outcome(state, move.start, [&](double, const ConcurrentMdp::StartOutcome& outcome) {
          if (outcome.ends)
            ended = true;
          else
            next.push_back(outcome.next);
        });
      } else {
        random.for_each_step_outcome(state, move.refine,
                                     [&](double, const ConcurrentState& outcome) { next.push_back(outcome); });
      }
      if (ended || next.empty()) break;
      state = next[generator() % next.size()];
    }
  }
  EXPECT_GT(checked, 2 * instances);  // random walks of several states each
}

// On instance 2 the untrained actor starts too soon (0.58); trained in the mode it learns better
// moves, and stays a policy of the model (never above the concurrent optimum, 0.72).
TEST(ConcurrentPpo, LearnsToActWhilePlanningOnInstanceTwo) {
  const ConcurrentMdp mdp(testing::paper_instance("instance2"));
  const double optimum = concurrent_optimum(mdp);
  const double untrained = exact_of(mdp, train_ppo(mdp, 1, 1).policy);
  const PpoTraining training = train_ppo(mdp, 1'000, 1);
  const double trained = exact_of(mdp, training.policy);
  EXPECT_LT(untrained, 0.6);
  EXPECT_GT(trained, untrained + 0.05);
  EXPECT_LE(trained, optimum + 1e-12);
  EXPECT_EQ(training.policy.acting, Acting::concurrent);
  EXPECT_EQ(training.curve.back().episodes, 1'000U);
}

// The policy's episodes (ConcurrentSession, the episode runner) agree with its exact value, on an
// instance with backtracking and one with chains.
TEST(ConcurrentPpo, EpisodesAgreeWithTheExactValue) {
  const std::vector<Problem> problems = {testing::with_backtracking(testing::random_instance(31, 3, 3, 9), 31),
                                         testing::door_open_at_even_steps()};
  for (const Problem& problem : problems) {
    SCOPED_TRACE(problem.name());
    const ConcurrentMdp mdp(problem);
    const auto policy = std::make_shared<const PpoPolicy>(train_ppo(mdp, 100, 2, small_epochs()).policy);
    ConcurrentPpoAllocator allocator(mdp, policy);
    const double exact = evaluate_exactly(mdp, allocator).expected_reward;
    EXPECT_LE(exact, concurrent_optimum(mdp) + 1e-12);
    MonteCarloOptions options;
    options.episodes = static_cast<std::uint64_t>(testing::repetitions_to_check(4'000));
    options.seed = 5;
    const MonteCarloResult result = run_monte_carlo(
        mdp, [&] { return std::make_unique<ConcurrentPpoAllocator>(mdp, policy); }, options);
    const double sigma = std::sqrt(std::max(exact * (1 - exact), 1e-4) / static_cast<double>(options.episodes));
    EXPECT_NEAR(result.mean_reward, exact, 4 * sigma);
  }
}

// A policy file says the mode it was trained in and reads back the same; a policy of one mode is
// refused by the other mode's allocator, naming the rule; the same seed trains the same bytes.
TEST(ConcurrentPpo, PolicyFilesSayTheirModeAndEachModeRefusesTheOther) {
  const Problem problem = testing::paper_instance("instance2");
  const ConcurrentMdp mdp(problem);
  const Mdp plan_first(problem);
  const PpoPolicy concurrent = train_ppo(mdp, 60, 9, small_epochs()).policy;
  const std::string bytes = ppo_policy_to_json(concurrent);
  EXPECT_NE(bytes.find("\"acting\": \"concurrent\""), std::string::npos);
  EXPECT_EQ(bytes, ppo_policy_to_json(train_ppo(mdp, 60, 9, small_epochs()).policy));
  EXPECT_NE(bytes, ppo_policy_to_json(train_ppo(mdp, 60, 10, small_epochs()).policy));
  const PpoPolicy read = parse_ppo_policy(bytes, "concurrent-policy");
  EXPECT_EQ(read.acting, Acting::concurrent);
  EXPECT_EQ(ppo_policy_to_json(read), bytes);
  EXPECT_EQ(exact_of(mdp, read), exact_of(mdp, concurrent));

  const PpoPolicy plan_first_policy = train_ppo(plan_first, 60, 9, small_epochs()).policy;
  EXPECT_EQ(ppo_policy_to_json(plan_first_policy).find("\"acting\""), std::string::npos);
  EXPECT_NE(message_of([&] {
              PpoAllocator(plan_first, std::make_shared<const PpoPolicy>(concurrent));
            }).find("trained acting while planning ('paper-instance-2'), not plan-first (SPEC §10)"),
            std::string::npos);
  EXPECT_NE(message_of([&] { ConcurrentPpoAllocator(mdp, std::make_shared<const PpoPolicy>(plan_first_policy)); })
                .find("trained plan-first ('paper-instance-2'), not acting while planning (SPEC §10): train it "
                      "with --act concurrent"),
            std::string::npos);
  // A file whose networks do not fit its mode, or whose mode is not one, is refused at its place.
  std::string reshaped = bytes;
  reshaped.replace(reshaped.find("\"acting\": \"concurrent\""), 22, "\"acting\": \"plan-first\"");
  EXPECT_THROW((void)parse_ppo_policy(reshaped, "reshaped"), InputError);
  std::string unknown = bytes;
  unknown.replace(unknown.find("\"acting\": \"concurrent\""), 22, "\"acting\": \"eventually\"");
  try {
    (void)parse_ppo_policy(unknown, "unknown");
    ADD_FAILURE() << "an unknown mode was read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("acting"), std::string::npos) << error.what();
  }
}

// The registry's ppo takes the mode with its own commit rule, from a policy file.
TEST(ConcurrentPpo, TheRegistryMakesItFromAPolicyFile) {
  const Problem problem = testing::paper_instance("instance2");
  const ConcurrentMdp mdp(problem);
  EXPECT_FALSE(allocator_registry().find("ppo").commit_rule.empty());
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "ontime-concurrent-ppo-test.json";
  const PpoPolicy policy = train_ppo(mdp, 60, 9, small_epochs()).policy;
  save_ppo_policy(policy, file);
  const ConcurrentAllocatorFactory factory = make_concurrent_allocator_factory("ppo", mdp, {{"policy", file.string()}});
  const auto made = factory();
  ConcurrentSolver evaluation(mdp, [&](const ConcurrentState& state) { return made->choose(state); });
  EXPECT_EQ(evaluation.solve(mdp.start()), exact_of(mdp, policy));
  EXPECT_NE(message_of([&] { (void)make_concurrent_allocator_factory("ppo", mdp); }).find("ppo needs a trained policy"),
            std::string::npos);
  // A policy trained on instance 5 acting while planning is refused on instance 2.
  const ConcurrentMdp other(testing::paper_instance("instance5"));
  save_ppo_policy(train_ppo(other, 20, 1, small_epochs()).policy, file);
  EXPECT_THROW((void)make_concurrent_allocator_factory("ppo", mdp, {{"policy", file.string()}}), UsageError);
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace ontime
