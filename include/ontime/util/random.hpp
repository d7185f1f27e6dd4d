#pragma once
// Seeded random numbers whose values are fixed by the seed alone, on every platform and
// for every thread count.
//
// Written here rather than taken from <random>: std::mt19937_64 costs ~2.5 KB of state and
// a slow seeding per episode, and the standard distributions (uniform_real_distribution,
// discrete_distribution) are implementation-defined, so the same seed could give other
// numbers with another standard library. SplitMix64 (Steele, Lea, Flood 2014) is a
// 64-bit-state generator that passes BigCrush and can be seeded in O(1) per episode.

#include <cstddef>
#include <cstdint>
#include <limits>

namespace ontime {

class SplitMix64 {
 public:
  using result_type = std::uint64_t;

  // The generator whose state starts at `seed`; any value is a valid seed.
  explicit constexpr SplitMix64(std::uint64_t seed) noexcept : state_(seed) {}

  // The smallest value a draw returns (UniformRandomBitGenerator).
  static constexpr result_type min() noexcept { return 0; }
  // The largest value a draw returns: every 64-bit value may come.
  static constexpr result_type max() noexcept { return std::numeric_limits<result_type>::max(); }

  // The next 64-bit draw; advances the state by one step.
  constexpr result_type operator()() noexcept {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

 private:
  std::uint64_t state_;
};

// A uniform double in [0, 1) from the top 53 bits of one draw.
template <class Generator>
constexpr double uniform01(Generator& generator) noexcept {
  return static_cast<double>(generator() >> 11) * 0x1.0p-53;
}

// An inverse-CDF draw over masses given one by one (a policy's choice, an outcome of the MDP):
// an index in [0, count) (count >= 1) where index i has probability `probability(i)` (the
// probabilities sum to about 1). One uniform draw; when rounding leaves it beyond the summed
// masses, the last index. (A Distribution draws its steps through its own quantile.)
template <class Probability, class Generator>
constexpr std::size_t sample_index(std::size_t count, Probability&& probability, Generator& generator) {
  double u = uniform01(generator);
  for (std::size_t i = 0; i + 1 < count; ++i) {
    const double mass = probability(i);
    if (u < mass) return i;
    u -= mass;
  }
  return count - 1;
}

// The seed of stream `index` derived from a master seed: episodes, threads and rollouts
// get independent streams whose values do not depend on which thread runs them.
constexpr std::uint64_t stream_seed(std::uint64_t master_seed, std::uint64_t index) noexcept {
  SplitMix64 mixer(master_seed ^ (0xd1b54a32d192ed03ULL * (index + 1)));
  mixer();
  return mixer();
}

}  // namespace ontime
