// Instances with exogenous chains (SPEC §9): chains declared, executions by a chain's state, actions
// that expire; read, checked with their places, and written back.
#include <gtest/gtest.h>

#include <string>

#include "ontime/model/instance_io.hpp"
#include "ontime/util/error.hpp"
#include "support/chain_reference.hpp"

namespace ontime {
namespace {

const std::string kCoffee = R"({"deadline": 12,
  "chains": {"queue": {"states": ["short", "long"], "start": "short",
                       "transitions": [[0.7, 0.3], [0.4, 0.6]]},
             "door": {"states": ["open", "locked"], "start": "open", "transitions": [[0.9, 0.1], [0, 1]]}},
  "actions": {
    "go": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"2": 1.0}}},
    "wait": {"planning": {"pmf": {"1": 1.0}},
             "execution": {"chain": "queue", "by_state": {"long": {"pmf": {"5": 1.0}}, "short": {"pmf": {"1": 1.0}}}}},
    "enter": {"planning": {"pmf": {"2": 1.0}}, "execution": {"pmf": {"1": 1.0}},
              "expires": {"after": 10, "chain": "door", "states": ["locked"]}}},
  "skeletons": [["go", "wait", "enter"], ["go"]]})";

TEST(ChainInstance, ChainsExecutionsByStateAndExpiryReadAndWriteBack) {
  const Problem problem = parse_problem(kCoffee, "coffee.json");
  ASSERT_TRUE(problem.has_chains());
  ASSERT_EQ(problem.chains().size(), 2U);
  EXPECT_EQ(problem.chains()[0].name, "queue");
  const int wait = problem.find_action("wait");
  const int enter = problem.find_action("enter");
  EXPECT_EQ(problem.execution_chain(wait), 0);
  EXPECT_EQ(problem.execution_chain(enter), -1);
  // By the chain's order of states, whatever the file's order.
  EXPECT_EQ(problem.action(wait).execution_by_state[0].pmf(1), 1.0);
  EXPECT_EQ(problem.action(wait).execution_by_state[1].pmf(5), 1.0);
  EXPECT_EQ(problem.action(enter).start_by, 10);
  EXPECT_EQ(problem.blocking_chain(enter), 1);
  EXPECT_FALSE(problem.blocks(enter, 0));
  EXPECT_TRUE(problem.blocks(enter, 1));
  EXPECT_TRUE(problem.action(enter).is_timed());
  EXPECT_FALSE(problem.action(problem.find_action("go")).is_timed());
  const std::string written = problem_to_json(problem);
  EXPECT_EQ(problem_to_json(parse_problem(written, "again.json")), written);
}

TEST(ChainInstance, BrokenChainsAndReferencesAreRefusedWithTheirPlace) {
  const auto place_of = [](std::string text) -> std::string {
    try {
      parse_problem(text, "bad.json");
    } catch (const InputError& error) {
      return error.place() + ": " + error.rule();
    }
    return "accepted";
  };
  const auto changed = [](const std::string& from, const std::string& to) {
    std::string text = kCoffee;
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  EXPECT_EQ(place_of(changed("[[0.7, 0.3], [0.4, 0.6]]", "[[0.7, 0.4], [0.4, 0.6]]")),
            "chains.queue.transitions[0]: the probabilities of leaving state 'short' sum to 1 (got 1.1)");
  EXPECT_EQ(place_of(changed("[[0.7, 0.3], [0.4, 0.6]]", "[[0.7, 0.3], [-0.4, 1.4]]")).substr(0, 30),
            "chains.queue.transitions[1][0]");
  EXPECT_EQ(place_of(changed(R"("chain": "queue")", R"("chain": "line")")),
            "actions.wait.execution.chain: no chain named 'line' is declared");
  EXPECT_EQ(place_of(changed(R"("long": {"pmf": {"5": 1.0}}, )", "")),
            "actions.wait.execution.by_state: missing the chain's state 'long'");
  EXPECT_EQ(place_of(changed(R"("long": {"pmf")", R"("huge": {"pmf")")),
            "actions.wait.execution.by_state.huge: the chain 'queue' has no such state");
  EXPECT_EQ(place_of(changed(R"("states": ["locked"])", R"("states": ["shut"])")),
            "actions.enter.expires: no state 'shut'");
  EXPECT_EQ(place_of(changed(R"("chain": "door")", R"("chain": "gate")")), "actions.enter.expires: no such chain");
  EXPECT_EQ(place_of(changed(R"("after": 10)", R"("after": 13)")),
            "actions.enter.expires: the last step to start must lie between 0 and the deadline (got 13)");
  EXPECT_EQ(place_of(changed(R"("after": 10, "chain": "door", "states": ["locked"])", R"("chain": "door")")),
            "actions.enter.expires: 'chain' and 'states' come together");
  EXPECT_EQ(place_of(changed(R"("start": "open")", R"("start": "ajar")")),
            "chains.door.start: 'ajar' is not one of the chain's states");
}

// The reference recursion of SPEC §9 (the yardstick of the solvers to come) on cases valued by hand.
TEST(ChainInstance, TheReferenceValuesHandMadeCases) {
  const auto instance = testing::queue_wait_instance;
  // Refined in step 1; the queue at step 1 is short w.p. 0.7 (done at 2 <= 4), long w.p. 0.3 (6 > 4).
  EXPECT_DOUBLE_EQ(testing::ChainReferenceSolver(instance("")).optimum(), 0.7);
  // It cannot start after step 0: it never starts.
  EXPECT_DOUBLE_EQ(testing::ChainReferenceSolver(instance(R"(, "expires": {"after": 0})")).optimum(), 0.0);
  // It cannot start while the queue is long: the same 0.7 (long ones missed the deadline anyway).
  EXPECT_DOUBLE_EQ(
      testing::ChainReferenceSolver(instance(R"(, "expires": {"chain": "queue", "states": ["long"]})")).optimum(), 0.7);
  // Behind a move: both refined by step 2, the move runs from 2 to 3 and the wait starts at 3,
  // done at once when the queue is short there, else at 8 > 4.
  const Problem behind = parse_problem(R"({"deadline": 4,
      "chains": {"queue": {"states": ["short", "long"], "start": "short", "transitions": [[0.7, 0.3], [0.4, 0.6]]}},
      "actions": {"move": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"1": 1.0}}},
        "wait": {"planning": {"pmf": {"1": 1.0}},
          "execution": {"chain": "queue", "by_state": {"short": {"pmf": {"0": 1.0}}, "long": {"pmf": {"5": 1.0}}}}}},
      "skeletons": [["move", "wait"]]})",
                                       "behind.json");
  const double p2 = 0.7 * 0.7 + 0.3 * 0.4;        // short at 2
  const double p3 = p2 * 0.7 + (1.0 - p2) * 0.4;  // short at 3
  EXPECT_NEAR(testing::ChainReferenceSolver(behind).optimum(), p3, 1e-15);
}

}  // namespace
}  // namespace ontime
