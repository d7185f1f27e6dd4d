#include "ontime/model/exogenous_chain.hpp"

#include <gtest/gtest.h>

#include <string>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

ExogenousChain door() {
  ExogenousChain chain;
  chain.name = "door";
  chain.states = {"open", "closed"};
  chain.start = 0;
  chain.transitions = {{0.9, 0.1}, {0.5, 0.5}};
  return chain;
}

// The chain file of `door()` with `replace` replaced by `with`.
std::string door_text(const std::string& replace = "", const std::string& with = "") {
  std::string text = chain_to_json(door());
  if (!replace.empty()) {
    const std::size_t at = text.find(replace);
    EXPECT_NE(at, std::string::npos) << replace;
    if (at != std::string::npos) text.replace(at, replace.size(), with);
  }
  return text;
}

void expect_refused(const std::string& text, const std::string& place, const std::string& rule) {
  try {
    (void)parse_chain(text, "door.json");
    ADD_FAILURE() << "accepted: " << text;
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "door.json");
    EXPECT_EQ(error.place(), place) << error.what();
    EXPECT_NE(error.rule().find(rule), std::string::npos) << error.what();
  }
}

TEST(ExogenousChain, AChainFileReadsBackBitForBit) {
  ExogenousChain chain = door();
  chain.transitions = {{1.0 / 3, 2.0 / 3}, {0.1 + 0.2, 1 - (0.1 + 0.2)}};
  chain.start = 1;
  const ExogenousChain read = parse_chain(chain_to_json(chain), "door.json");
  EXPECT_EQ(read.name, "door");
  EXPECT_EQ(read.states, chain.states);
  EXPECT_EQ(read.start, 1);
  EXPECT_EQ(read.transitions, chain.transitions);  // exact doubles
  EXPECT_EQ(chain_to_json(read), chain_to_json(chain));
  EXPECT_EQ(read.state_index("closed"), 1);
  EXPECT_EQ(read.state_index("ajar"), -1);
}

TEST(ExogenousChain, EveryBrokenRuleIsNamedWithItsPlace) {
  expect_refused(door_text("[0.9,0.1]", "[0.9,0.2]"), "transitions[0]", "sum to 1 (got 1.1");
  expect_refused(door_text("[0.5,0.5]", "[1.5,-0.5]"), "transitions[1][1]", "finite number >= 0");
  expect_refused(door_text("[0.5,0.5]", "[0.5]"), "transitions[1]", "one entry per state (2, got 1)");
  expect_refused(door_text(",\n    [0.5,0.5]", ""), "transitions", "one row per state (2 rows, got 1)");
  expect_refused(door_text("\"start\": \"open\"", "\"start\": \"ajar\""), "start", "'ajar' is not one of");
  expect_refused(door_text("\"closed\"\n", "\"open\"\n"), "states[1]", "'open' is named twice");
  expect_refused(door_text("\"closed\"\n", "\"\"\n"), "states[1]", "not empty");
  expect_refused(door_text("\"version\": 1", "\"version\": 2"), "version", "reads version 1");
  expect_refused(door_text("ontime-chain", "ontime-model"), "format", "not a chain file");
  expect_refused(door_text("\"name\": \"door\"", "\"name\": \"door\", \"rate\": 3"), "rate", "unknown key");
  expect_refused(door_text("[0.9,0.1]", "[0.9,\"0.1\"]"), "transitions[0][1]", "is a number");
  expect_refused(door_text("\"states\"", "\"statez\""), "statez", "unknown key");
  // NaN and infinities are not JSON, and a number too large for a double is refused too.
  EXPECT_THROW((void)parse_chain(door_text("[0.9,0.1]", "[1e999,0.1]"), "door.json"), InputError);
  // A chain built in code: the same rules, as UsageError.
  ExogenousChain broken = door();
  broken.transitions[1][0] = 0.6;
  EXPECT_THROW((void)chain_to_json(broken), UsageError);
  const std::optional<ChainFault> fault = find_chain_fault(broken);
  ASSERT_TRUE(fault.has_value());
  EXPECT_EQ(fault->place, "transitions[1]");
  EXPECT_FALSE(find_chain_fault(door()).has_value());
}

TEST(ExogenousChain, ItsDistributionAfterSomeStepsIsTheMatrixPower) {
  // From open: [0.9, 0.1], then [0.9 * 0.9 + 0.1 * 0.5, 0.9 * 0.1 + 0.1 * 0.5] = [0.86, 0.14].
  EXPECT_EQ(chain_distribution(door(), 0, 0), (std::vector<double>{1.0, 0.0}));
  EXPECT_EQ(chain_distribution(door(), 0, 1), (std::vector<double>{0.9, 0.1}));
  const std::vector<double> two = chain_distribution(door(), 0, 2);
  EXPECT_DOUBLE_EQ(two[0], 0.86);
  EXPECT_DOUBLE_EQ(two[1], 0.14);
  // Towards the stationary distribution, [5/6, 1/6] (0.1 * pi_open = 0.5 * pi_closed).
  const std::vector<double> far = chain_distribution(door(), 1, 200);
  EXPECT_NEAR(far[0], 5.0 / 6, 1e-12);
  EXPECT_NEAR(far[1], 1.0 / 6, 1e-12);
  EXPECT_THROW((void)chain_distribution(door(), 2, 1), UsageError);
  EXPECT_THROW((void)chain_distribution(door(), 0, -1), UsageError);
}

}  // namespace
}  // namespace ontime
