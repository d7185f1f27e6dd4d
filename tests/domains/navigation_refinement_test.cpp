#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "ontime/domains/navigation.hpp"
#include "ontime/domains/navigation_collision.hpp"
#include "support/paper.hpp"

namespace ontime::domains {
namespace {

const NavigationDomain& office_domain() {
  static const NavigationDomain domain(load_navigation_world(testing::source_path("data/domains/navigation.json")));
  return domain;
}

EffortSettings checks() { return EffortSettings{EffortUnit::collision_checks, 1200.0}; }

// Runs a refinement to the end, one step of `step` seconds at a time, for at most `steps`.
bool run(Refinement& refinement, double step, int steps) {
  for (int s = 1; s <= steps; ++s) {
    if (refinement.advance(step * s) == RefinementStatus::found) return true;
  }
  return false;
}

Pose pose(const Configuration& configuration) {
  return Pose{configuration.at(0), configuration.at(1), configuration.at(2)};
}

TEST(NavigationRefinement, FindsACollisionFreeMotionThatConnectsItsEndpoints) {
  const NavigationDomain& domain = office_domain();
  const NavigationWorld& world = domain.world();
  // The bare footprint (no clearance), checked every 5 mm and 0.005 rad along each segment:
  // four times finer than the planner's checks, which also kept a 2 cm clearance.
  const NavigationCollision bare(world, 0.0);
  Configuration start = domain.initial_configuration();
  for (const std::string& action : world.skeletons[1]) {
    const auto refinement = domain.refine(action, start, 7, checks());
    ASSERT_TRUE(run(*refinement, 3.0, 200)) << action;
    const std::vector<Configuration> motion = refinement->motion();
    ASSERT_GE(motion.size(), 2u);
    EXPECT_EQ(motion.front(), start) << action;
    EXPECT_EQ(motion.back(), refinement->final_configuration()) << action;
    const Room& target = world.room(move_rooms(action)[1]);
    const Pose end = pose(motion.back());
    EXPECT_TRUE(target.contains(end.x, end.y)) << action;
    std::vector<Pose> poses;
    for (std::size_t i = 0; i < motion.size(); ++i) {
      poses.push_back(pose(motion[i]));
      if (i == 0) continue;
      const Pose a = pose(motion[i - 1]), b = pose(motion[i]);
      const double turn = std::remainder(b.theta - a.theta, 2 * std::numbers::pi);
      const int pieces =
          1 + static_cast<int>(std::max(std::hypot(b.x - a.x, b.y - a.y) / 0.005, std::abs(turn) / 0.005));
      for (int k = 0; k <= pieces; ++k) {
        const double f = static_cast<double>(k) / pieces;
        const Pose between{a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), a.theta + f * turn};
        ASSERT_FALSE(bare.collides(between)) << action << ": segment " << i << " at " << f;
      }
    }
    EXPECT_DOUBLE_EQ(refinement->execution_seconds(), domain.execution_seconds(poses));
    EXPECT_GT(refinement->execution_seconds(), 0.0);
    start = refinement->final_configuration();
  }
}

TEST(NavigationRefinement, ExecutionTimeIsLengthOverSpeedPlusRotationOverAngularSpeed) {
  const NavigationDomain& domain = office_domain();
  // 3 m straight, then a quarter turn on the spot, then 4 m with a half turn (shortest way).
  const std::vector<Pose> poses{{0, 0, 0}, {3, 0, 0}, {3, 0, std::numbers::pi / 2}, {3, 4, -std::numbers::pi / 2}};
  const double length = 7.0, rotation = std::numbers::pi / 2 + std::numbers::pi;
  EXPECT_NEAR(domain.execution_seconds(poses),
              length / domain.world().robot.linear_speed + rotation / domain.world().robot.angular_speed, 1e-12);
}

TEST(NavigationRefinement, ResumesTheSamePlannerSliceBySlice) {
  const NavigationDomain& domain = office_domain();
  const auto refinement = domain.refine("move(R1,R2)", domain.initial_configuration(), 3, checks());
  const double step = 3.0;
  std::uint64_t previous = 0;
  int slices = 0;
  while (refinement->status() == RefinementStatus::working && slices < 200) {
    ++slices;
    refinement->advance(step * slices);
    const std::uint64_t checks_now = refinement->effort().checks();
    EXPECT_GT(checks_now, previous);  // every slice works on
    if (refinement->status() == RefinementStatus::working) {
      // A slice stops at its limit (one planner iteration of overshoot at most).
      EXPECT_GE(checks_now, static_cast<std::uint64_t>(std::round(step * slices * 1200)));
      EXPECT_LT(checks_now, static_cast<std::uint64_t>(std::round(step * slices * 1200)) + 2000);
    }
    previous = checks_now;
  }
  ASSERT_EQ(refinement->status(), RefinementStatus::found);
  EXPECT_GT(slices, 1) << "this seed finds the narrow door of R1-R2 after several steps";
  // Once found, more effort changes nothing.
  refinement->advance(step * (slices + 5));
  EXPECT_EQ(refinement->effort().checks(), previous);
  EXPECT_DOUBLE_EQ(refinement->effort().seconds(), static_cast<double>(previous) / 1200.0);
}

TEST(NavigationRefinement, SameSeedSameMotionAndEffort) {
  const NavigationDomain& domain = office_domain();
  const auto first = domain.refine("move(R5,R8)", domain.fallback_start("move(R5,R8)", 4), 11, checks());
  const auto second = domain.refine("move(R5,R8)", domain.fallback_start("move(R5,R8)", 4), 11, checks());
  ASSERT_TRUE(run(*first, 3.0, 100));
  ASSERT_TRUE(run(*second, 3.0, 100));
  EXPECT_EQ(first->effort().checks(), second->effort().checks());
  EXPECT_EQ(first->motion(), second->motion());
  const auto other = domain.refine("move(R5,R8)", domain.fallback_start("move(R5,R8)", 4), 12, checks());
  ASSERT_TRUE(run(*other, 3.0, 100));
  EXPECT_NE(first->motion(), other->motion());
}

TEST(NavigationRefinement, WallClockEffortCountsSeconds) {
  const NavigationDomain& domain = office_domain();
  const auto refinement = domain.refine("move(R2,R3)", domain.fallback_start("move(R2,R3)", 1), 5,
                                        EffortSettings{EffortUnit::wall_clock, 1200.0});
  ASSERT_TRUE(run(*refinement, 1.0, 10));
  EXPECT_GT(refinement->effort().seconds(), 0.0);
  EXPECT_LT(refinement->effort().seconds(), 10.0);
  EXPECT_GT(refinement->effort().checks(), 0u);
}

TEST(NavigationRefinement, RejectsBadRequests) {
  const NavigationDomain& domain = office_domain();
  EXPECT_THROW(domain.refine("move(R1,R99)", domain.initial_configuration(), 1, checks()), std::invalid_argument);
  EXPECT_THROW(domain.refine("jump(R1,R2)", domain.initial_configuration(), 1, checks()), std::invalid_argument);
  // The start must lie in the room the move leaves, and be free.
  EXPECT_THROW(domain.refine("move(R2,R3)", domain.initial_configuration(), 1, checks()), std::invalid_argument);
  EXPECT_THROW(domain.refine("move(R1,R2)", Configuration{0.2, 11.3, 0.0}, 1, checks()), std::invalid_argument);
  EXPECT_THROW(domain.refine("move(R1,R2)", Configuration{1.0, 2.0}, 1, checks()), std::invalid_argument);
}

TEST(EffortMeter, ConvertsChecksToSecondsAndStopsExactly) {
  EffortMeter meter(EffortSettings{EffortUnit::collision_checks, 1200.0});
  for (int i = 0; i < 3599; ++i) meter.count_check();
  EXPECT_FALSE(meter.reached(3.0));
  meter.count_check();
  EXPECT_TRUE(meter.reached(3.0));
  EXPECT_DOUBLE_EQ(meter.seconds(), 3.0);
  EXPECT_EQ(parse_effort_unit("wall"), EffortUnit::wall_clock);
  EXPECT_EQ(effort_unit_name(EffortUnit::collision_checks), "checks");
  EXPECT_THROW(parse_effort_unit("minutes"), std::invalid_argument);
}

}  // namespace
}  // namespace ontime::domains
