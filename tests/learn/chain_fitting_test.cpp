#include "ontime/learn/chain_fitting.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime {
namespace {

ChainRun chain_run(std::vector<std::string> states, std::string sequence = "s", std::int64_t first_step = 0) {
  return ChainRun{"test", std::move(sequence), first_step, std::move(states)};
}

// A queue's run drawn from the birth-death chain itself (seeded).
ChainRun simulated_queue(double arrival, double service, int capacity, int steps, std::uint64_t seed) {
  SplitMix64 random(seed);
  ChainRun run = chain_run({}, "simulated");
  int n = 0;
  for (int t = 0; t < steps; ++t) {
    run.states.push_back(std::to_string(n));
    const double draw = uniform01(random);
    const double in = n < capacity ? arrival : 0.0;
    const double out = n > 0 ? service : 0.0;
    if (draw < in) {
      ++n;
    } else if (draw < in + out) {
      --n;
    }
  }
  return run;
}

TEST(ChainFitting, MarkovRowsAreTheCountsOfTheTransitionsSeen) {
  // A->B, B->B, B->A, A->B: row A is [0, 1], row B [1/2, 1/2].
  const std::vector<ChainRun> runs{chain_run({"A", "B", "B", "A", "B"})};
  ChainFitOptions options;
  options.name = "door";
  const ChainFit fit = fit_chain(runs, options);
  EXPECT_EQ(fit.chain.states, (std::vector<std::string>{"A", "B"}));
  EXPECT_EQ(fit.chain.transitions, (std::vector<std::vector<double>>{{0.0, 1.0}, {0.5, 0.5}}));
  EXPECT_EQ(fit.chain.start, 0);
  EXPECT_EQ(fit.chain.name, "door");
  EXPECT_EQ(fit.transitions, 4u);
  EXPECT_DOUBLE_EQ(fit.log_likelihood, 2 * std::log(0.5));
  // A prior of one pseudo-transition per entry: row A (0 + 1) / (2 + 2), (2 + 1) / (2 + 2).
  options.prior = 1.0;
  const ChainFit smoothed = fit_chain(runs, options);
  EXPECT_EQ(smoothed.chain.transitions, (std::vector<std::vector<double>>{{0.25, 0.75}, {0.5, 0.5}}));
  // States listed: their order, and a state never seen needs the prior.
  options.states = {"B", "A", "C"};
  const ChainFit listed = fit_chain(runs, options);
  EXPECT_EQ(listed.chain.states, options.states);
  EXPECT_EQ(listed.chain.transitions[1], (std::vector<double>{3.0 / 5, 1.0 / 5, 1.0 / 5}));
  EXPECT_EQ(listed.chain.transitions[2], (std::vector<double>{1.0 / 3, 1.0 / 3, 1.0 / 3}));
  EXPECT_EQ(listed.chain.start, 1);
  options.prior = 0.0;
  try {
    (void)fit_chain(runs, options);
    ADD_FAILURE() << "a state without a row was accepted";
  } catch (const UsageError& error) {
    EXPECT_NE(std::string(error.what()).find("state 'C' is never seen followed by another"), std::string::npos)
        << error.what();
  }
  options.states = {"A"};
  EXPECT_THROW((void)fit_chain(runs, options), InputError);  // B is not listed
}

TEST(ChainFitting, NumberedStatesAreInNumericOrderAndTheStartIsTheCommonestFirst) {
  const std::vector<ChainRun> runs{chain_run({"10", "9", "2", "10"}, "a"), chain_run({"9", "10", "2", "9"}, "b"),
                                   chain_run({"9", "2"}, "c")};
  const ChainFit fit = fit_chain(runs, ChainFitOptions{});
  EXPECT_EQ(fit.chain.states, (std::vector<std::string>{"2", "9", "10"}));
  EXPECT_EQ(fit.chain.start, 1);  // "9" begins two of the three sequences
  EXPECT_EQ(fit.runs, 3u);
  EXPECT_EQ(fit.transitions, 7u);
}

TEST(ChainFitting, ALogSplitsIntoRunsAtGapsAndNamesItsBrokenLines) {
  const std::string log =
      "{\"sequence\": \"mon\", \"step\": 0, \"state\": 0}\n"
      "{\"sequence\": \"tue\", \"step\": 5, \"state\": \"2\"}\n"
      "\n"
      "{\"sequence\": \"mon\", \"step\": 1, \"state\": 1}\n"
      "{\"sequence\": \"mon\", \"step\": 3, \"state\": 1}\n"
      "{\"step\": 7, \"state\": 1}\n"
      "{\"sequence\": \"tue\", \"step\": 6, \"state\": 1}\n";
  const std::vector<ChainRun> runs = parse_chain_observations(log, "queue.jsonl");
  ASSERT_EQ(runs.size(), 4u);
  EXPECT_EQ(runs[0].sequence, "mon");
  EXPECT_EQ(runs[0].states, (std::vector<std::string>{"0", "1"}));
  EXPECT_EQ(runs[1].sequence, "tue");
  EXPECT_EQ(runs[1].first_step, 5);
  EXPECT_EQ(runs[1].states, (std::vector<std::string>{"2", "1"}));
  EXPECT_EQ(runs[2].first_step, 3);  // after a gap
  EXPECT_EQ(runs[3].sequence, "");
  EXPECT_EQ(runs[0].source, "queue.jsonl");

  const auto refused = [](const std::string& text, const std::string& place, const std::string& rule) {
    try {
      (void)parse_chain_observations(text, "queue.jsonl");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& error) {
      EXPECT_EQ(error.place(), place) << error.what();
      EXPECT_NE(error.rule().find(rule), std::string::npos) << error.what();
    }
  };
  refused("{\"step\": 3, \"state\": 0}\n{\"step\": 3, \"state\": 1}\n", "line 2: step",
          "after the sequence's previous step, 3 (got 3)");
  refused("{\"step\": 0, \"state\": -1}\n", "line 1: state", "a state's name or a whole number >= 0");
  refused("{\"step\": 0, \"state\": 1.5}\n", "line 1: state", "a state's name or a whole number >= 0");
  refused("{\"step\": -2, \"state\": 1}\n", "line 1: step", "whole number of steps >= 0");
  refused("{\"step\": 0, \"state\": 1, \"queue\": 2}\n", "line 1: queue", "unknown key");
  refused("{\"step\": 0}\n", "line 1", "missing required key 'state'");
  try {
    (void)parse_chain_observations("{\"step\": 0, \"state\": 1\n", "queue.jsonl");
    ADD_FAILURE() << "a broken line was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place().rfind("line 1, column ", 0), 0u) << error.what();
  }
  refused("\n\n", "file", "no observations");
}

TEST(ChainFitting, ABirthDeathQueueHasTheClosedFormWhereTheCountsAllowIt) {
  // 0 1 1 2 1 0 0 1 under capacity 3: up 3, down 2, a stay at 0 and one in between, none at 3.
  // The likelihood factors: arrival 3 / (3 + 1 + 2 + 1), service (1 - arrival) * 2 / (2 + 1).
  const std::vector<ChainRun> runs{chain_run({"0", "1", "1", "2", "1", "0", "0", "1"})};
  ChainFitOptions options;
  options.kind = ChainKind::birth_death;
  options.capacity = 3;
  const ChainFit fit = fit_chain(runs, options);
  EXPECT_DOUBLE_EQ(fit.arrival, 3.0 / 7);
  EXPECT_DOUBLE_EQ(fit.service, 4.0 / 7 * 2.0 / 3);
  ASSERT_EQ(fit.chain.state_count(), 4);
  EXPECT_EQ(fit.chain.states[3], "3");
  EXPECT_DOUBLE_EQ(fit.chain.transitions[0][1], fit.arrival);
  EXPECT_DOUBLE_EQ(fit.chain.transitions[0][0], 1 - fit.arrival);
  EXPECT_DOUBLE_EQ(fit.chain.transitions[2][1], fit.service);
  EXPECT_DOUBLE_EQ(fit.chain.transitions[3][3], 1 - fit.service);
  EXPECT_EQ(fit.chain.transitions[0][2], 0.0);
  EXPECT_FALSE(find_chain_fault(fit.chain).has_value());
  // Without a capacity: the longest queue seen, 2.
  options.capacity = 0;
  EXPECT_EQ(fit_chain(runs, options).chain.state_count(), 3);
  // No arrival seen: arrival 0 and the service from the downs alone.
  const ChainFit draining = fit_chain(std::vector<ChainRun>{chain_run({"3", "2", "2", "1", "0", "0"})}, options);
  EXPECT_EQ(draining.arrival, 0.0);
  EXPECT_DOUBLE_EQ(draining.service, 3.0 / (3 + 1));  // downs over downs and stays away from 0
}

TEST(ChainFitting, ABirthDeathQueueElsewhereIsAtTheLikelihoodsMaximum) {
  // Every kind of step seen, stays at 0 and at the capacity among them: the optimiser's answer.
  const std::vector<ChainRun> runs{chain_run({"0", "0", "1", "2", "2", "2", "1", "2", "1", "1", "0", "1", "2"})};
  ChainFitOptions options;
  options.kind = ChainKind::birth_death;
  const ChainFit fit = fit_chain(runs, options);
  // up 5, down 3, stays: at 0 one, between one (1 -> 1), at the capacity (2) two.
  const double up = 5, down = 3, empty = 1, between = 1, full = 2;
  const double a = fit.arrival, s = fit.service;
  // The first-order conditions of the log-likelihood in (arrival, service).
  EXPECT_NEAR(up / a - empty / (1 - a) - between / (1 - a - s), 0.0, 1e-6 * up / a);
  EXPECT_NEAR(down / s - full / (1 - s) - between / (1 - a - s), 0.0, 1e-6 * down / s);
  const auto log_likelihood = [&](double x, double y) {
    return up * std::log(x) + down * std::log(y) + empty * std::log(1 - x) + full * std::log(1 - y) +
           between * std::log(1 - x - y);
  };
  EXPECT_NEAR(fit.log_likelihood, log_likelihood(a, s), 1e-12);
  // No point of a fine grid does better.
  for (int i = 1; i < 1000; ++i) {
    for (int j = 1; i + j < 1000; ++j) {
      ASSERT_LE(log_likelihood(i / 1000.0, j / 1000.0), fit.log_likelihood + 1e-12) << i << " " << j;
    }
  }
}

TEST(ChainFitting, ASimulatedQueueIsFoundAgain) {
  const double arrival = 0.2, service = 0.3;
  const std::vector<ChainRun> runs{simulated_queue(arrival, service, 6, 20'000, 7)};
  ChainFitOptions options;
  options.kind = ChainKind::birth_death;
  options.capacity = 6;
  const ChainFit fit = fit_chain(runs, options);
  // Five standard errors of a proportion over the steps that could have moved each way (the
  // queue is empty about a third of the time, full rarely).
  const auto steps = static_cast<double>(fit.transitions);
  EXPECT_NEAR(fit.arrival, arrival, 5 * std::sqrt(arrival * (1 - arrival) / (0.9 * steps)));
  EXPECT_NEAR(fit.service, service, 5 * std::sqrt(service * (1 - service) / (0.5 * steps)));
  // The same seed, the same bytes.
  EXPECT_EQ(
      chain_to_json(fit_chain(std::vector<ChainRun>{simulated_queue(arrival, service, 6, 20'000, 7)}, options).chain),
      chain_to_json(fit.chain));
}

TEST(ChainFitting, ObservationsABirthDeathQueueCannotExplainAreNamed) {
  ChainFitOptions options;
  options.kind = ChainKind::birth_death;
  const auto refused = [&options](const ChainRun& run, const std::string& place, const std::string& rule) {
    try {
      (void)fit_chain(std::vector<ChainRun>{run}, options);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& error) {
      EXPECT_EQ(error.source(), "test");
      EXPECT_EQ(error.place(), place) << error.what();
      EXPECT_NE(error.rule().find(rule), std::string::npos) << error.what();
    }
  };
  refused(chain_run({"0", "1", "3"}, "mon", 10), "sequence 'mon', step 12", "goes from 1 to 3 in one step");
  refused(chain_run({"0", "many"}, "mon"), "sequence 'mon', step 1", "a whole number (got 'many')");
  options.capacity = 2;
  refused(chain_run({"1", "2", "3"}, "mon"), "sequence 'mon', step 2", "above the capacity of 2");
  options.capacity = 0;
  EXPECT_THROW((void)fit_chain(std::vector<ChainRun>{chain_run({"0"})}, options), UsageError);  // no transition
  options.states = {"0", "1"};
  EXPECT_THROW((void)fit_chain(std::vector<ChainRun>{chain_run({"0", "1"})}, options), UsageError);
  ChainFitOptions markov;
  markov.prior = -1;
  EXPECT_THROW((void)fit_chain(std::vector<ChainRun>{chain_run({"0", "1"})}, markov), UsageError);
  markov.prior = 0;
  markov.states = {"0", "0"};
  EXPECT_THROW((void)fit_chain(std::vector<ChainRun>{chain_run({"0", "1"})}, markov), UsageError);
  EXPECT_EQ(chain_kind("birth-death"), ChainKind::birth_death);
  EXPECT_THROW((void)chain_kind("poisson"), UsageError);
}

}  // namespace
}  // namespace ontime
