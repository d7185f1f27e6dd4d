// Chain averaging (model/chain_averaging.hpp): the mean occupancy and the averaged instance,
// against values computed by hand or in closed form.
#include "ontime/model/chain_averaging.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "ontime/model/instance_io.hpp"
#include "ontime/util/error.hpp"

namespace ontime {
namespace {

int action_named(const Problem& problem, const std::string& id) {
  for (int a = 0; a < problem.action_count(); ++a) {
    if (problem.action(a).id == id) return a;
  }
  ADD_FAILURE() << "no action " << id;
  return 0;
}

TEST(ChainAveraging, MeanOccupancyOfAnAbsorbingChainByHand) {
  // From "a": steps 0, 1, 2 give (1, 0), (1/2, 1/2), (1/4, 3/4).
  const ExogenousChain chain{.name = "door", .states = {"a", "b"}, .start = 0, .transitions = {{0.5, 0.5}, {0, 1}}};
  const std::vector<double> mean = mean_occupancy(chain, 0, 2);
  ASSERT_EQ(mean.size(), 2U);
  EXPECT_DOUBLE_EQ(mean[0], 1.75 / 3);
  EXPECT_DOUBLE_EQ(mean[1], 1.25 / 3);
  EXPECT_EQ(mean_occupancy(chain, 1, 5), (std::vector<double>{0, 1}));
  EXPECT_EQ(mean_occupancy(chain, 0, 0), (std::vector<double>{1, 0}));
  EXPECT_THROW((void)mean_occupancy(chain, 2, 1), UsageError);
  EXPECT_THROW((void)mean_occupancy(chain, 0, -1), UsageError);
}

// The example of data/instances/chains: a queue (short 0.7 -> short, long 0.6 -> long) and a door
// that locks for good with probability 0.05 per step; D = 12.
TEST(ChainAveraging, TheMeetingExampleAveragedInClosedForm) {
  const Problem real =
      load_problem(std::string(ONTIME_SOURCE_DIR) + "/data/instances/chains/meeting-through-the-queue.json");
  const Problem averaged = average_chains(real);
  const Steps deadline = real.deadline();
  ASSERT_EQ(deadline, 12);
  const double horizon = static_cast<double>(deadline + 1);
  // P(short at t) = 4/7 + (3/7) 0.3^t (stationary 4/7, second eigenvalue 0.3).
  const double short_weight = 4.0 / 7 + (3.0 / 7) * (1 - std::pow(0.3, horizon)) / (0.7 * horizon);
  // P(open at t) = 0.95^t.
  const double open_weight = (1 - std::pow(0.95, horizon)) / (0.05 * horizon);

  ASSERT_EQ(averaged.chains().size(), 2U);
  for (const ExogenousChain& chain : averaged.chains()) {
    EXPECT_EQ(chain.states, (std::vector<std::string>{kAveragedChainState}));
    EXPECT_EQ(chain.transitions, (std::vector<std::vector<double>>{{1.0}}));
  }
  // The wait is still drawn when it starts, from the mixture.
  const Action& wait = averaged.action(action_named(averaged, "wait"));
  EXPECT_EQ(wait.execution_chain, "queue");
  ASSERT_EQ(wait.execution_by_state.size(), 1U);
  EXPECT_NEAR(wait.execution_by_state[0].pmf(1), short_weight, 1e-15);
  EXPECT_NEAR(wait.execution_by_state[0].pmf(4), 0.5 * (1 - short_weight), 1e-15);
  EXPECT_NEAR(wait.execution_by_state[0].pmf(6), 0.5 * (1 - short_weight), 1e-15);
  // Entering is blocked while the door is locked: that weight becomes a finish past the deadline;
  // its last start (step 11) is kept.
  const Action& enter = averaged.action(action_named(averaged, "enter"));
  EXPECT_TRUE(enter.blocking_chain.empty());
  EXPECT_TRUE(enter.execution_chain.empty());
  EXPECT_EQ(enter.start_by, 11);
  EXPECT_NEAR(enter.execution.pmf(1), open_weight, 1e-15);
  EXPECT_NEAR(enter.execution.pmf(deadline + 1), 1 - open_weight, 1e-15);
  // Walking had no last start: a vacuous one (D) keeps it timed, so the states keep their layout.
  const Action& walk = averaged.action(action_named(averaged, "walk"));
  EXPECT_EQ(walk.start_by, deadline);
  EXPECT_NEAR(walk.execution.pmf(3), open_weight, 1e-15);
  EXPECT_EQ(averaged.timed_slot_count(), real.timed_slot_count());
  for (int a = 0; a < real.action_count(); ++a) EXPECT_EQ(averaged.timed_slot(a), real.timed_slot(a)) << a;
  // Over a longer horizon, the long-run mix: 101 steps from short.
  const Problem long_run = average_chains(real, 100);
  const double long_short = 4.0 / 7 + (3.0 / 7) * (1 - std::pow(0.3, 101.0)) / (0.7 * 101);
  // (101 rounded steps and sums: a few ulps each.)
  EXPECT_NEAR(long_run.action(action_named(long_run, "wait")).execution_by_state[0].pmf(1), long_short,
              101 * 4 * std::numeric_limits<double>::epsilon());
  EXPECT_THROW((void)average_chains(real, -1), UsageError);
  // The rest is the instance's.
  EXPECT_EQ(averaged.skeleton_lists(), real.skeleton_lists());
  EXPECT_EQ(averaged.reward(1).per_step, real.reward(1).per_step);
  EXPECT_EQ(averaged.action(action_named(averaged, "go")).execution.pmf(2), 1.0);
}

TEST(ChainAveraging, AChainThatBothDrawsAndBlocksFailsItsBlockedWeight) {
  const Problem real = parse_problem(R"({"deadline": 3,
      "chains": {"line": {"states": ["free", "busy", "closed"], "start": "free",
                          "transitions": [[0, 1, 0], [0, 0, 1], [0, 0, 1]]}},
      "actions": {"serve": {"planning": {"pmf": {"1": 1.0}},
                            "execution": {"chain": "line", "by_state": {"free": {"pmf": {"0": 1.0}},
                                          "busy": {"pmf": {"2": 1.0}}, "closed": {"pmf": {"1": 1.0}}}},
                            "expires": {"chain": "line", "states": ["closed"]}}},
      "skeletons": [["serve"]]})",
                                     "line.json");
  // Steps 0..3: free, busy, closed, closed.
  const Problem averaged = average_chains(real);
  const Action& serve = averaged.action(0);
  ASSERT_EQ(serve.execution_by_state.size(), 1U);
  EXPECT_EQ(serve.execution_by_state[0].pmf(0), 0.25);
  EXPECT_EQ(serve.execution_by_state[0].pmf(1), 0.0);
  EXPECT_EQ(serve.execution_by_state[0].pmf(2), 0.25);
  EXPECT_EQ(serve.execution_by_state[0].pmf(4), 0.5);
  EXPECT_EQ(serve.start_by, kNever);
}

TEST(ChainAveraging, AProblemWithoutChainsIsUnchanged) {
  const Problem real = parse_problem(R"({"deadline": 5,
      "actions": {"a": {"planning": {"pmf": {"1": 0.5, "2": 0.5}}, "execution": {"pmf": {"3": 1.0}},
                        "expires": {"after": 2}}},
      "skeletons": [["a"]], "rewards": [0.5]})",
                                     "static.json");
  const Problem averaged = average_chains(real);
  EXPECT_FALSE(averaged.has_chains());
  EXPECT_EQ(averaged.action(0).start_by, 2);
  EXPECT_EQ(averaged.action(0).planning.pmf(2), 0.5);
  EXPECT_EQ(averaged.reward(0).value, 0.5);
}

}  // namespace
}  // namespace ontime
