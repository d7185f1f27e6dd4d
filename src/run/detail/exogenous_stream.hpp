#pragma once
// The random stream a session's simulated exogenous chains (SPEC §9) are drawn from, plan-first
// (Session) and acting while planning (ConcurrentSession) alike: a stream of the session's seed of
// its own, so that the allocator's draws stay those of the same seed without chains.

#include <cstdint>

#include "ontime/util/random.hpp"

namespace ontime::detail {

// The generator of the chains' steps (and of the executions drawn from them) of the session seeded
// with `seed`. O(1).
inline SplitMix64 exogenous_stream(std::uint64_t seed) noexcept { return SplitMix64(stream_seed(seed, 0x65786f67)); }

}  // namespace ontime::detail
