// Table I's computation (run/table.hpp) and its report (report/report.hpp): the cells are the
// single evaluations' numbers, the optimum is exact or a certified interval raised to the row's
// best exact value, and bad requests stop before any work.

#include "ontime/run/table.hpp"

#include <gtest/gtest.h>

#include "ontime/allocators/optimal.hpp"
#include "ontime/report/report.hpp"
#include "ontime/run/evaluation.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"

namespace ontime {
namespace {

TableInstance paper_row(const std::string& name, ParameterValues parameters = {}) {
  return {testing::paper_instance(name), testing::source_path("data/instances/paper/" + name + ".json").string(), name,
          std::move(parameters)};
}

TEST(Table, CellsAreTheEvaluationsOfEachColumnAndTheOptimumIsExact) {
  const std::vector<TableInstance> rows{paper_row("instance1"), paper_row("instance3")};
  TableOptions options;
  options.solvers = {"dp-rerun", "round-robin"};
  options.exact = true;
  options.episodes = 500;
  options.seed = 9;
  options.threads = 2;
  check_table_request(rows, options);
  const Table table = measure_table(rows, options);
  ASSERT_EQ(table.rows.size(), 2U);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const Mdp mdp(rows[r].problem);
    for (std::size_t c = 0; c < options.solvers.size(); ++c) {
      MonteCarloOptions alone;
      alone.episodes = 500;
      alone.seed = 9;
      alone.threads = 1;
      const AllocatorFactory factory = make_allocator_factory(options.solvers[c], mdp);
      const MonteCarloResult expected = run_monte_carlo(mdp, factory, alone);
      const TableCell& cell = table.rows[r].cells[c];
      EXPECT_EQ(cell.sampled.successes, expected.successes) << r << " " << c;
      const auto allocator = factory();
      ASSERT_TRUE(cell.exact && cell.exact->value);
      EXPECT_EQ(*cell.exact->value, evaluate_exactly(mdp, *allocator).success_probability);
    }
    OptimalSolver solver(mdp);
    ASSERT_TRUE(table.rows[r].optimum && table.rows[r].optimum->value);
    EXPECT_NEAR(*table.rows[r].optimum->value, solver.solve(mdp.start()), 1e-12);
  }
  // instance1: dp-rerun 0.9400, optimum 0.9420 (docs/experiments.md).
  EXPECT_NEAR(*table.rows[0].cells[0].exact->value, 0.94, 5e-5);
  EXPECT_NEAR(*table.rows[0].optimum->value, 0.942, 5e-5);
  const std::string markdown = report::to_markdown(table);
  EXPECT_NE(markdown.find("| instance1 "), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("(0.9400)"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("past parameter 'max-states'"), std::string::npos) << markdown;
}

TEST(Table, AnOptimumPastItsCapIsAnIntervalRaisedToTheBestExactCell) {
  // A cap of 100 states: instance1's optimum needs 872, dp-rerun's exact value 40.
  const std::vector<TableInstance> rows{paper_row("instance1", {{"max-states", "100"}})};
  TableOptions options;
  options.solvers = {"dp-rerun", "round-robin"};
  options.exact = true;
  options.episodes = 50;
  const Table table = measure_table(rows, options);
  const ExactPart& optimum = *table.rows[0].optimum;
  EXPECT_TRUE(optimum.cap_reached);
  EXPECT_FALSE(optimum.value);
  ASSERT_TRUE(optimum.lower && optimum.upper);
  // round-robin needs 143 states: over the cap, reported as such.
  EXPECT_TRUE(table.rows[0].cells[1].exact->cap_reached);
  EXPECT_FALSE(table.rows[0].cells[1].exact->value);
  const double dp_rerun = *table.rows[0].cells[0].exact->value;
  EXPECT_GE(*optimum.lower, dp_rerun);
  EXPECT_LE(*optimum.lower, 0.942 + 1e-12);
  EXPECT_GE(*optimum.upper, 0.942 - 1e-12);
  EXPECT_NE(report::to_markdown(table).find("cap reached"), std::string::npos);
}

TEST(Table, BadRequestsStopBeforeAnyWork) {
  const std::vector<TableInstance> rows{paper_row("instance1")};
  TableOptions options;
  options.solvers = {"dp", ""};
  EXPECT_THROW(check_table_request(rows, options), UsageError);
  options.solvers = {"dp", "dp"};
  try {
    check_table_request(rows, options, [](std::string_view name) { return "--" + std::string(name); });
    FAIL() << "a repeated column was accepted";
  } catch (const UsageError& error) {
    EXPECT_EQ(std::string(error.what()), "--solvers: 'dp' is given twice (one column per allocator)");
  }
  options.solvers = {"dp"};
  EXPECT_THROW(check_table_request({paper_row("instance1"), paper_row("instance1")}, options), UsageError);
  EXPECT_NO_THROW(check_table_request(rows, options));
  EXPECT_THROW(check_table_request({}, options), UsageError);
}

}  // namespace
}  // namespace ontime
