#include "ontime/solve/contiguous_success.hpp"

#include <gtest/gtest.h>

#include "ontime/allocators/dp.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"
#include "support/random_instances.hpp"

namespace ontime {
namespace {

TEST(ContiguousSuccess, SingleActionSkeletonsOfInstanceFour) {
  const Problem problem = testing::paper_instance("instance4");
  const Mdp mdp(problem);
  const ContiguousSuccessTable table(mdp, Aggregation::sum);
  // Execution takes 1 step, D = 4: success iff planning takes at most 3 steps.
  EXPECT_DOUBLE_EQ(table.success_probability(0, 0, 0, 0), 0.3 + 0.15 + 0.1);
  EXPECT_DOUBLE_EQ(table.success_probability(1, 0, 0, 0), 0.1 + 0.8);
  // After one unsuccessful step on a1_1 (CT = 1): steps 2 and 3 remain useful, given T > 1.
  EXPECT_DOUBLE_EQ(table.success_probability(0, 0, 1, 1), (0.15 + 0.1) / 0.7);
  // Time already used elsewhere counts against the deadline: CT = 2 leaves t <= 1 from PT = 0.
  EXPECT_DOUBLE_EQ(table.success_probability(1, 0, 0, 2), 0.0);
  EXPECT_DOUBLE_EQ(table.success_probability(0, 0, 0, 2), 0.3);
  EXPECT_DOUBLE_EQ(table.success_probability(0, 0, 0, 4), 0.0);
}

TEST(ContiguousSuccess, AggregationsOnFigureOne) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  // PS(sigma1) = p(d1 = 1) e(1) * AGG(PS(sigma1, 1, 1, 1), PS(sigma2, 1, 1, 1)), each 0.5.
  const ContiguousSuccessTable sum(mdp, Aggregation::sum);
  const ContiguousSuccessTable max(mdp, Aggregation::max);
  const ContiguousSuccessTable self(mdp, Aggregation::self);
  EXPECT_DOUBLE_EQ(sum.success_probability(0, 0, 0, 0), 0.25);
  EXPECT_DOUBLE_EQ(sum.success_probability(1, 0, 0, 0), 0.25);
  EXPECT_DOUBLE_EQ(max.success_probability(0, 0, 0, 0), 0.125);
  EXPECT_DOUBLE_EQ(self.success_probability(0, 0, 0, 0), 0.125);
  for (const ContiguousSuccessTable* table : {&sum, &max, &self}) {
    EXPECT_DOUBLE_EQ(table->success_probability(2, 0, 0, 0), 0.5);  // d3: 3 steps, then 1 of {1, 10}
    EXPECT_DOUBLE_EQ(table->success_probability(0, 1, 0, 2), 0.5);  // d12 at CT + ET = 2
  }
}

TEST(ContiguousSuccess, ParsesAggregationNames) {
  EXPECT_EQ(parse_aggregation("sum"), Aggregation::sum);
  EXPECT_EQ(parse_aggregation("max"), Aggregation::max);
  EXPECT_EQ(parse_aggregation("self"), Aggregation::self);
  EXPECT_THROW(parse_aggregation("mean"), UsageError);
  EXPECT_EQ(to_string(Aggregation::max), "max");
}

// With `self`, PS(k, 0, 0, 0) is the success probability of refining k alone, contiguously:
// the exact value of the allocator that always chooses k (when no other skeleton completes
// on k's path, which could only add to it).
TEST(ContiguousSuccess, SelfEqualsExactValueOfRefiningOneSkeleton) {
  int compared = 0;
  for (std::uint64_t seed = 1; seed <= 150; ++seed) {
    const Problem problem = testing::random_instance(seed);
    const Mdp mdp(problem);
    const ContiguousSuccessTable table(mdp, Aggregation::self);
    for (int k = 0; k < problem.skeleton_count(); ++k) {
      DpAllocator always_k(k);
      const double exact = evaluate_exactly(mdp, always_k).success_probability;
      const double predicted = table.success_probability(k, 0, 0, 0);
      bool prefix_completes = false;
      for (int l = 0; l + 1 < problem.skeleton_length(k); ++l) {
        prefix_completes = prefix_completes || problem.completes_a_skeleton(problem.action_at(k, l));
      }
      if (prefix_completes) {
        EXPECT_LE(predicted, exact + 1e-12) << "seed " << seed << " skeleton " << k;
      } else {
        EXPECT_NEAR(predicted, exact, 1e-12) << "seed " << seed << " skeleton " << k;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 200);
}

}  // namespace
}  // namespace ontime
