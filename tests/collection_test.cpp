#include <gtest/gtest.h>

#include <map>

#include "ontime/domains/collection.hpp"
#include "ontime/domains/navigation.hpp"
#include "ontime/fitting.hpp"
#include "ontime/planner_log.hpp"
#include "support/mini_world.hpp"
#include "support/paper.hpp"

namespace ontime::domains {
namespace {

const NavigationDomain& office() {
  static const NavigationDomain domain(load_navigation_world(testing::source_path("data/domains/navigation.json")));
  return domain;
}

CollectionOptions options(std::uint64_t trials, std::uint64_t seed, unsigned threads) {
  CollectionOptions result;
  result.trials = trials;
  result.seed = seed;
  result.threads = threads;
  result.effort = EffortSettings{EffortUnit::collision_checks, 1200.0};
  result.step_seconds = 3.0;
  result.budget_steps = 22;
  return result;
}

std::string text(const std::vector<RefinementAttempt>& log) {
  std::string all;
  for (const RefinementAttempt& attempt : log) all += planner_log_line(attempt);
  return all;
}

TEST(Collection, TheSkeletonTreeListsParentsFirst) {
  const std::vector<TreeAction> tree = skeleton_tree(office().skeletons());
  ASSERT_EQ(tree.size(), 15u);  // 16 positions, move(R1,R5) shared
  EXPECT_EQ(tree[0].action, "move(R1,R2)");
  EXPECT_EQ(tree[1].action, "move(R1,R5)");
  EXPECT_EQ(tree[2].action, "move(R1,R10)");
  for (std::size_t a = 0; a < tree.size(); ++a) {
    if (tree[a].parent >= 0) {
      EXPECT_LT(static_cast<std::size_t>(tree[a].parent), a);
      // The parent's move ends where this one starts.
      EXPECT_EQ(move_rooms(tree[static_cast<std::size_t>(tree[a].parent)].action)[1], move_rooms(tree[a].action)[0]);
    } else {
      EXPECT_EQ(move_rooms(tree[a].action)[0], "R1");
    }
  }
}

TEST(Collection, TheCheckUnitGivesIdenticalLogsForIdenticalSeedsWhateverTheThreads) {
  const CollectionResult one = collect(office(), options(3, 9, 1));
  const CollectionResult two = collect(office(), options(3, 9, 2));
  ASSERT_EQ(one.log.size(), 45u);
  EXPECT_EQ(text(one.log), text(two.log));
  EXPECT_EQ(one.collision_checks, two.collision_checks);
  const CollectionResult other = collect(office(), options(3, 10, 2));
  EXPECT_NE(text(one.log), text(other.log));
}

TEST(Collection, LogsEveryAttemptWithItsEffortAndCutsOffAtTheBudget) {
  CollectionOptions settings = options(4, 2, 2);
  settings.budget_steps = 2;  // 7200 checks: the narrow doors are often cut off
  const CollectionResult result = collect(office(), settings);
  ASSERT_EQ(result.log.size(), 60u);
  std::size_t cut_off = 0;
  for (std::size_t i = 0; i < result.log.size(); ++i) {
    const RefinementAttempt& attempt = result.log[i];
    EXPECT_EQ(attempt.trial, i % 4);
    ASSERT_TRUE(attempt.collision_checks.has_value());
    EXPECT_NEAR(attempt.planning_seconds, static_cast<double>(*attempt.collision_checks) / 1200.0, 5e-7);
    if (attempt.found) {
      EXPECT_GT(attempt.execution_seconds, 0.0);
    } else {
      ++cut_off;
      EXPECT_GE(*attempt.collision_checks, 7200u);
      EXPECT_EQ(whole_steps_within(attempt.planning_seconds, 3.0), 2);
    }
  }
  EXPECT_GT(cut_off, 0u);
}

TEST(Collection, DrawsAFallbackStartWhenNoRefinementOfTheParentSucceeded) {
  CollectionOptions settings = options(2, 1, 1);
  settings.budget_steps = 1;
  settings.effort.checks_per_second = 20;  // 60 checks a step: hardly anything is found
  const CollectionResult result = collect(office(), settings);
  ASSERT_EQ(result.log.size(), 30u);  // every action still gets its attempts
  const std::vector<TreeAction> tree = skeleton_tree(office().skeletons());
  std::map<std::string, int> found;
  for (const RefinementAttempt& attempt : result.log) found[attempt.action] += attempt.found ? 1 : 0;
  int orphans = 0;  // actions refined although no refinement of their parent succeeded
  for (const TreeAction& node : tree) {
    if (node.parent >= 0 && found[tree[static_cast<std::size_t>(node.parent)].action] == 0) ++orphans;
  }
  EXPECT_GT(orphans, 0);
}

TEST(Collection, RefinesAWholeSkeletonForPictures) {
  const auto motions = refine_skeleton(office(), office().skeletons()[3], 1, options(1, 1, 1));
  ASSERT_EQ(motions.size(), 4u);
  for (std::size_t l = 1; l < motions.size(); ++l) EXPECT_EQ(motions[l].front(), motions[l - 1].back());
  EXPECT_EQ(motions[0].front(), office().initial_configuration());
}

}  // namespace
}  // namespace ontime::domains
