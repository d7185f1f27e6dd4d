// Work split over ranks (ranks.hpp), with ranks played by threads: the shares, the packing of
// what ranks exchange, and Monte Carlo episodes that give one process's numbers on any number
// of ranks.

#include "ontime/util/ranks.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/run/experiments.hpp"
#include "ontime/util/byte_packing.hpp"
#include "support/paper.hpp"
#include "support/thread_ranks.hpp"

namespace ontime {
namespace {

TEST(Ranks, RanksTakeInterleavedUnitsAndTogetherEveryUnitOnce) {
  for (const std::uint64_t count : {0ULL, 1ULL, 2ULL, 7ULL, 100ULL, 1001ULL}) {
    for (const int size : {1, 2, 3, 8}) {
      std::vector<int> taken(count, 0);
      std::uint64_t smallest = count, largest = 0;
      for (int rank = 0; rank < size; ++rank) {
        const RankUnits units = rank_units(count, rank, size);
        for (std::uint64_t i = 0; i < units.count; ++i) {
          ASSERT_LT(units.unit(i), count);
          ++taken[units.unit(i)];
          if (i > 0) {
            EXPECT_EQ(units.unit(i) - units.unit(i - 1), static_cast<std::uint64_t>(size));
          }
        }
        smallest = std::min(smallest, units.count);
        largest = std::max(largest, units.count);
      }
      EXPECT_EQ(std::count(taken.begin(), taken.end(), 1), static_cast<std::ptrdiff_t>(count)) << count << " " << size;
      EXPECT_LE(largest - smallest, 1u);
    }
  }
  const RankUnits alone = rank_units(10, nullptr);
  EXPECT_EQ(alone.count, 10u);
  EXPECT_EQ(alone.unit(9), 9u);
  EXPECT_EQ(rank_units(10, 2, 3).unit(0), 2u);
  EXPECT_EQ(rank_units(10, 2, 3).count, 3u);  // 2, 5, 8
}

TEST(Ranks, PackedValuesReadBackInOrderAndAShortBufferIsAnError) {
  struct Plain {
    int a;
    double b;
  };
  BytePacker packer;
  packer.put(std::uint64_t{42});
  packer.put_string("move(R1,R5)");
  packer.put_vector(std::vector<double>{0.5, -1.25, 3.0});
  packer.put(Plain{7, 2.5});
  packer.put_vector(std::vector<int>{});
  ByteUnpacker unpacker(packer.bytes());
  EXPECT_EQ(unpacker.get<std::uint64_t>(), 42u);
  EXPECT_EQ(unpacker.get_string(), "move(R1,R5)");
  EXPECT_EQ(unpacker.get_vector<double>(), (std::vector<double>{0.5, -1.25, 3.0}));
  const auto plain = unpacker.get<Plain>();
  EXPECT_EQ(plain.a, 7);
  EXPECT_EQ(plain.b, 2.5);
  EXPECT_TRUE(unpacker.get_vector<int>().empty());
  EXPECT_TRUE(unpacker.done());
  EXPECT_THROW(unpacker.get<char>(), std::runtime_error);
  const std::string cut = packer.bytes().substr(0, 12);
  ByteUnpacker short_one(cut);
  short_one.get<std::uint64_t>();
  EXPECT_THROW(short_one.get_string(), std::runtime_error);
}

TEST(Ranks, ThreadRanksGatherEveryRanksBytesInRankOrderRoundAfterRound) {
  std::mutex mutex;
  std::vector<std::vector<std::string>> seen;
  testing::run_on_ranks(3, [&](const Ranks& ranks) {
    for (int round = 0; round < 50; ++round) {
      const auto all = ranks.all_gather(std::to_string(round) + ":" + std::to_string(ranks.rank()));
      const std::vector<std::string> expected{std::to_string(round) + ":0", std::to_string(round) + ":1",
                                              std::to_string(round) + ":2"};
      if (all != expected) {
        const std::lock_guard lock(mutex);
        seen.push_back(all);
      }
    }
  });
  EXPECT_TRUE(seen.empty());
}

// Every rank returns one process's totals, and every rank is told of every episode once.
TEST(Ranks, MonteCarloEpisodesSplitOverRanksGiveOneProcesssNumbers) {
  const Problem problem = testing::paper_instance("instance3");
  const Mdp mdp(problem);
  const AllocatorFactory factory = make_allocator_factory("mcts", mdp, {{"iterations", "200"}});
  MonteCarloOptions options;
  options.episodes = 301;  // not a multiple of the rank counts
  options.seed = 77;
  options.threads = 2;
  std::vector<int> alone(options.episodes, -1);
  options.on_episode = [&](std::uint64_t episode, const EpisodeResult& result) { alone[episode] = result.steps_used; };
  const MonteCarloResult one = run_monte_carlo(mdp, factory, options);
  ASSERT_GT(one.successes, 0u);
  ASSERT_LT(one.successes, options.episodes);
  for (const int size : {1, 2, 3}) {
    std::mutex mutex;
    std::vector<MonteCarloResult> results(static_cast<std::size_t>(size));
    std::vector<std::vector<int>> steps(static_cast<std::size_t>(size), std::vector<int>(options.episodes, -1));
    testing::run_on_ranks(size, [&](const Ranks& ranks) {
      MonteCarloOptions split = options;
      split.threads = 1;
      split.ranks = &ranks;
      std::vector<int>& mine = steps[static_cast<std::size_t>(ranks.rank())];
      split.on_episode = [&](std::uint64_t episode, const EpisodeResult& result) {
        EXPECT_EQ(mine[episode], -1) << "episode " << episode << " twice";
        mine[episode] = result.steps_used;
      };
      MonteCarloResult result = run_monte_carlo(mdp, factory, split);
      const std::lock_guard lock(mutex);
      results[static_cast<std::size_t>(ranks.rank())] = std::move(result);
    });
    for (int rank = 0; rank < size; ++rank) {
      const MonteCarloResult& many = results[static_cast<std::size_t>(rank)];
      EXPECT_EQ(many.episodes, one.episodes);
      EXPECT_EQ(many.successes, one.successes) << size << " ranks, rank " << rank;
      EXPECT_EQ(many.success_rate, one.success_rate);
      EXPECT_EQ(many.ci95, one.ci95);
      EXPECT_EQ(many.decision_time.decisions, one.decision_time.decisions);
      EXPECT_EQ(many.statistics.find("iterations"), one.statistics.find("iterations")) << size;
      EXPECT_EQ(steps[static_cast<std::size_t>(rank)], alone) << size << " ranks, rank " << rank;
    }
  }
}

// The searcher's budget per decision is rank 0's measurement of the reference on every rank.
TEST(Ranks, AnEqualTimeStudyGivesEveryRankRankZerosBudget) {
  const Problem problem = testing::paper_instance("instance1");
  const Mdp mdp(problem);
  StudySettings settings;
  settings.episodes = 40;
  settings.threads = 1;
  settings.parameters = {{"iterations", "100"}};
  std::array<double, 2> budgets{};
  std::array<std::uint64_t, 2> reference_successes{};
  testing::run_on_ranks(2, [&](const Ranks& ranks) {
    StudySettings split = settings;
    split.ranks = &ranks;
    const EqualTimeStudy study = equal_time_study(mdp, split);
    budgets[static_cast<std::size_t>(ranks.rank())] = study.reference_decision_seconds;
    reference_successes[static_cast<std::size_t>(ranks.rank())] = study.reference.successes;
  });
  EXPECT_GT(budgets[0], 0.0);
  EXPECT_EQ(budgets[0], budgets[1]);
  EXPECT_EQ(reference_successes[0], reference_successes[1]);
  EXPECT_EQ(reference_successes[0], compute_time_study(mdp, settings).reference.successes);
}

}  // namespace
}  // namespace ontime
