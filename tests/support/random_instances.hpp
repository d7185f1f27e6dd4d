#pragma once
// Random small instances for property tests: a few skeletons sharing prefixes at random,
// short deadlines, supports with gaps and "never" mass. Same seed, same instance.

#include <cstdint>

#include "ontime/model/problem.hpp"

namespace ontime::testing {

Problem random_instance(std::uint64_t seed, int max_skeletons = 4, int max_length = 3, Steps max_deadline = 9);

// Exactly `skeleton_count` skeletons of at most `max_length` actions, built the same way.
Problem wide_instance(std::uint64_t seed, int skeleton_count, int max_length, Steps deadline);

}  // namespace ontime::testing
