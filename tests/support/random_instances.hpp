#pragma once
// Random small instances for property tests: a few skeletons sharing prefixes at random,
// short deadlines, supports with gaps and "never" mass. Same seed, same instance.

#include <cstdint>

#include "ontime/model/problem.hpp"

namespace ontime::testing {

Problem random_instance(std::uint64_t seed, int max_skeletons = 4, int max_length = 3, Steps max_deadline = 9);

// `problem` with one or two random exogenous chains of 2 or 3 states (some transitions 0), about a
// third of its actions' executions depending on a chain's state, about a third of them expiring
// (after a random step, in random states of a chain, or both) and, when `rewards`, a random
// reward per skeleton (SPEC §8, §9). Same seed, same instance.
Problem with_random_chains(const Problem& problem, std::uint64_t seed, bool rewards);

// `problem` where every action after the first of its path may backtrack (SPEC §7): a share beta
// of its attempts (drawn per action, up to 0.6) give up at one or two steps instead of finding,
// blaming one or two of its ancestors; about a quarter of the actions never do. Same seed, same
// instance.
Problem with_backtracking(const Problem& problem, std::uint64_t seed);

// `problem` with a random reward per skeleton (SPEC §8): a value in [0.2, 1], and for about half
// of them a fall per step that keeps the reward at the deadline at or above 0. Same seed, same
// rewards.
Problem with_random_rewards(const Problem& problem, std::uint64_t seed);

// How many of `count` repetitions (random instances, generated keys) a test checks: all of them,
// or the share named by the environment variable ONTIME_TEST_SHARE (in (0, 1], at least one). The
// sanitizer run sets 0.25: the first repetitions take the same code paths under the sanitizers at
// a quarter of the cost, and the release build checks them all.
int repetitions_to_check(int count);

// Exactly `skeleton_count` skeletons of at most `max_length` actions, built the same way.
Problem wide_instance(std::uint64_t seed, int skeleton_count, int max_length, Steps deadline);

}  // namespace ontime::testing
