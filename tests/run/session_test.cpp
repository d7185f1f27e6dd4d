#include "ontime/run/session.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

#include "ontime/allocators/optimal.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

// An allocator that replays a script and records what it observed.
class ScriptedAllocator final : public Allocator {
 public:
  explicit ScriptedAllocator(std::vector<int> script) : script_(std::move(script)) {}
  std::string_view name() const noexcept override { return "scripted"; }
  void begin_episode(std::uint64_t) override { ++episodes; }
  int choose(const State&) override { return script_.at(next_++); }
  void observe(const State&, int choice, const State& after, Status status) override {
    observed.push_back(choice);
    last_time = after.time;
    last_status = status;
  }
  bool is_stationary() const noexcept override { return false; }

  int episodes = 0;
  std::vector<int> observed;
  int last_time = -1;
  Status last_status = Status::running;

 private:
  std::vector<int> script_;
  std::size_t next_ = 0;
};

TEST(Session, DrivesTheOptimalPolicyOfFigureOneToSuccess) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  OptimalAllocator optimal(mdp);
  Session session(mdp, optimal);
  // The planner finds d1 in one step with a fast motion; d12's motion is slow; d22's is fast.
  Decision decision = session.choose();
  EXPECT_EQ(decision.skeleton, 0);
  EXPECT_EQ(problem.action(decision.action).id, "d1");
  EXPECT_EQ(session.report_refined(1), Status::running);
  decision = session.choose();
  EXPECT_EQ(problem.action(decision.action).id, "d12");
  EXPECT_EQ(session.report_refined(10), Status::running);
  decision = session.choose();
  EXPECT_EQ(problem.action(decision.action).id, "d22");
  EXPECT_EQ(session.report_refined(1), Status::success);
  EXPECT_EQ(session.solution(), 1);
  EXPECT_EQ(session.steps_used(), 3);
  EXPECT_THROW(session.choose(), std::logic_error);
}

TEST(Session, ReportsFailureAsSoonAsTheDeadlineIsOutOfReach) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  ScriptedAllocator allocator({0, 0, 0});
  Session session(mdp, allocator);
  EXPECT_EQ(allocator.episodes, 1);
  session.choose();
  EXPECT_EQ(session.report_not_yet(), Status::running);
  session.choose();
  EXPECT_EQ(session.report_not_yet(), Status::failure);  // nothing can fit in the 3 steps left
  EXPECT_EQ(session.solution(), -1);
  EXPECT_EQ(allocator.observed, (std::vector<int>{0, 0}));
  EXPECT_EQ(allocator.last_time, 2);
  EXPECT_EQ(allocator.last_status, Status::failure);
}

TEST(Session, RejectsMisuse) {
  const Problem problem = testing::paper_instance("figure1");
  const Mdp mdp(problem);
  ScriptedAllocator allocator({0, 0, 7});
  Session session(mdp, allocator);
  EXPECT_THROW(session.report_not_yet(), std::logic_error);  // no decision yet
  session.choose();
  EXPECT_THROW(session.choose(), std::logic_error);  // decision not reported
  EXPECT_THROW(session.report_refined(-3), UsageError);
  EXPECT_EQ(session.report_refined(1), Status::running);
  session.choose();
  EXPECT_EQ(session.report_refined(10), Status::running);
  EXPECT_THROW(session.choose(), UsageError);  // allocator answered skeleton 7
}

TEST(Session, IdleStepsCannotReportARefinement) {
  const Problem problem(
      "idle", 6, 1.0,
      {Action{"a", Distribution::from_pmf({0.0, 1.0}), Distribution::from_pmf({0, 0, 0, 0, 0, 0, 1.0})},
       Action{"b", Distribution::from_pmf({0.0, 0.0, 1.0}), Distribution::from_pmf({1.0})}},
      {{0}, {1}});
  const Mdp mdp(problem);
  ScriptedAllocator allocator({0, 0});
  Session session(mdp, allocator);
  session.choose();
  EXPECT_EQ(session.report_refined(6), Status::running);  // too slow to execute
  const Decision idle = session.choose();
  EXPECT_EQ(idle.action, -1);
  EXPECT_THROW(session.report_refined(1), UsageError);
  EXPECT_EQ(session.report_not_yet(), Status::running);
}

}  // namespace
}  // namespace ontime
