#include "support/random_instances.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "ontime/util/random.hpp"

namespace ontime::testing {
namespace {

int uniform_int(SplitMix64& generator, int low, int high) {
  return low + static_cast<int>(generator() % static_cast<std::uint64_t>(high - low + 1));
}

Distribution random_distribution(SplitMix64& generator, Steps first, Steps last) {
  std::vector<double> masses(static_cast<std::size_t>(last) + 1, 0.0);
  const int support = uniform_int(generator, 1, 3);
  double total = 0;
  for (int i = 0; i < support; ++i) {
    const auto step = static_cast<std::size_t>(uniform_int(generator, first, last));
    const double weight = 0.1 + uniform01(generator);
    masses[step] += weight;
    total += weight;
  }
  // A quarter of the distributions keep some "never" mass.
  const double scale = (generator() % 4 == 0) ? 0.6 + 0.3 * uniform01(generator) : 1.0;
  for (double& mass : masses) mass = mass / total * scale;
  return Distribution::from_pmf(std::move(masses));
}

Problem build_instance(SplitMix64& generator, std::string name, Steps deadline, int skeleton_count, int max_length) {
  std::vector<Action> actions;
  std::vector<std::vector<int>> skeletons;
  const auto new_action = [&] {
    Action action;
    action.id = std::to_string(actions.size());
    action.id.insert(0, 1, 'a');
    action.planning = random_distribution(generator, 1, deadline);
    action.execution = random_distribution(generator, 0, deadline / 2 + 1);
    actions.push_back(std::move(action));
    return static_cast<int>(actions.size()) - 1;
  };
  while (static_cast<int>(skeletons.size()) < skeleton_count) {
    std::vector<int> path;
    // Share a prefix of an earlier skeleton half of the time.
    if (!skeletons.empty() && generator() % 2 == 0) {
      const auto& other = skeletons[generator() % skeletons.size()];
      const int shared = uniform_int(generator, 1, static_cast<int>(other.size()));
      path.assign(other.begin(), other.begin() + shared);
    }
    const int length = uniform_int(generator, static_cast<int>(path.size()) + (path.empty() ? 1 : 0),
                                   std::max(static_cast<int>(path.size()) + 1, max_length));
    while (static_cast<int>(path.size()) < length) path.push_back(new_action());
    bool duplicate = false;
    for (const auto& existing : skeletons) duplicate = duplicate || existing == path;
    if (!duplicate) skeletons.push_back(std::move(path));
  }
  return Problem(std::move(name), deadline, 1.0, std::move(actions), std::move(skeletons));
}

}  // namespace

Problem random_instance(std::uint64_t seed, int max_skeletons, int max_length, Steps max_deadline) {
  SplitMix64 generator(seed);
  const Steps deadline = uniform_int(generator, 2, max_deadline);
  const int skeleton_count = uniform_int(generator, 1, max_skeletons);
  return build_instance(generator, "random-" + std::to_string(seed), deadline, skeleton_count, max_length);
}

Problem with_random_chains(const Problem& problem, std::uint64_t seed, bool rewards) {
  SplitMix64 generator(seed);
  std::vector<ExogenousChain> chains(static_cast<std::size_t>(uniform_int(generator, 1, 2)));
  for (std::size_t c = 0; c < chains.size(); ++c) {
    ExogenousChain& chain = chains[c];
    chain.name = std::to_string(c);
    chain.name.insert(0, "chain");
    const int states = uniform_int(generator, 2, 3);
    for (int s = 0; s < states; ++s) chain.states.push_back(std::to_string(s).insert(0, 1, 's'));
    chain.start = uniform_int(generator, 0, states - 1);
    for (int s = 0; s < states; ++s) {
      std::vector<double> row(static_cast<std::size_t>(states), 0.0);
      double total = 0;
      for (double& entry : row) {
        entry = generator() % 3 == 0 ? 0.0 : 0.1 + uniform01(generator);
        total += entry;
      }
      if (total == 0) {
        row[static_cast<std::size_t>(s)] = 1.0;
        total = 1.0;
      }
      for (double& entry : row) entry /= total;
      chain.transitions.push_back(std::move(row));
    }
  }
  std::vector<Action> actions(problem.actions().begin(), problem.actions().end());
  for (Action& action : actions) {
    if (generator() % 3 == 0) {
      const ExogenousChain& chain = chains[generator() % chains.size()];
      action.execution_chain = chain.name;
      for (int s = 0; s < chain.state_count(); ++s) {
        action.execution_by_state.push_back(random_distribution(generator, 0, problem.deadline() / 2 + 1));
      }
    }
    if (generator() % 3 == 0) {
      const auto kind = generator() % 3;
      if (kind != 1) action.start_by = uniform_int(generator, problem.deadline() / 3, problem.deadline());
      if (kind != 0) {
        const ExogenousChain& chain = chains[generator() % chains.size()];
        action.blocking_chain = chain.name;
        for (const std::string& state : chain.states) {
          if (generator() % 2 == 0) action.blocking_states.push_back(state);
        }
        if (action.blocking_states.empty()) action.blocking_states.push_back(chain.states.back());
      }
    }
  }
  std::vector<SkeletonReward> values;
  for (int k = 0; rewards && k < problem.skeleton_count(); ++k) {
    SkeletonReward reward{0.2 + 0.8 * uniform01(generator), 0.0};
    if (generator() % 2 == 0) reward.per_step = reward.value * uniform01(generator) / problem.deadline();
    values.push_back(reward);
  }
  return {problem.name() + "-chains", problem.deadline(),    problem.step_seconds(), std::move(actions),
          problem.skeleton_lists(),   problem.description(), std::move(values),      std::move(chains)};
}

Problem with_backtracking(const Problem& problem, std::uint64_t seed) {
  SplitMix64 generator(seed);
  std::vector<Action> actions(problem.actions().begin(), problem.actions().end());
  for (int a = 0; a < problem.action_count(); ++a) {
    std::vector<int> ancestors;
    for (int up = problem.parent(a); up >= 0; up = problem.parent(up)) ancestors.push_back(up);
    if (ancestors.empty() || generator() % 4 == 0) continue;
    Action& action = actions[static_cast<std::size_t>(a)];
    const double beta = 0.15 + 0.45 * uniform01(generator);
    std::vector<double> planning(action.planning.masses().begin(), action.planning.masses().end());
    for (double& mass : planning) mass *= 1.0 - beta;
    action.planning = Distribution::from_pmf(std::move(planning));
    std::vector<double> back(static_cast<std::size_t>(problem.deadline()) + 1, 0.0);
    const auto first = 1 + static_cast<std::size_t>(generator() % static_cast<std::uint64_t>(problem.deadline()));
    const auto second = 1 + static_cast<std::size_t>(generator() % static_cast<std::uint64_t>(problem.deadline()));
    back[first] += beta / 2;
    back[second] += beta / 2;
    action.backtrack = Distribution::from_pmf(std::move(back));
    const int blamed = ancestors[generator() % ancestors.size()];
    action.culprits = {{problem.action(blamed).id, 1.0}};
    if (ancestors.size() > 1 && generator() % 2 == 0) {
      const int other = ancestors
          [(static_cast<std::size_t>(std::find(ancestors.begin(), ancestors.end(), blamed) - ancestors.begin()) + 1) %
           ancestors.size()];
      action.culprits = {{problem.action(blamed).id, 0.7}, {problem.action(other).id, 0.3}};
    }
  }
  return problem.with_actions(std::move(actions));
}

Problem wide_instance(std::uint64_t seed, int skeleton_count, int max_length, Steps deadline) {
  SplitMix64 generator(seed);
  return build_instance(generator, "wide-" + std::to_string(skeleton_count), deadline, skeleton_count, max_length);
}

Problem with_random_rewards(const Problem& problem, std::uint64_t seed) {
  std::mt19937_64 generator(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<SkeletonReward> rewards;
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    SkeletonReward reward{0.2 + 0.8 * unit(generator), 0.0};
    if (unit(generator) < 0.5) reward.per_step = reward.value * unit(generator) / problem.deadline();
    rewards.push_back(reward);
  }
  return problem.with_rewards(rewards);
}

int repetitions_to_check(int count) {
  const char* share = std::getenv("ONTIME_TEST_SHARE");
  if (share == nullptr || *share == '\0') return count;
  char* end = nullptr;
  const double value = std::strtod(share, &end);
  if (end == share || *end != '\0' || !(value > 0.0 && value <= 1.0)) {
    ADD_FAILURE() << "ONTIME_TEST_SHARE: a number in (0, 1], got '" << share << "'";
    return count;
  }
  return std::max(1, static_cast<int>(std::ceil(value * count)));
}

}  // namespace ontime::testing
