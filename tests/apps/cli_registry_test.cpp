// The command line builds its allocator options from the registry: a kind added at run time
// (here a test-only one) shows its parameters in --help and takes values, with no CLI change.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "common.hpp"
#include "ontime/allocators/round_robin.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"
#include "support/process.hpp"

namespace ontime {
namespace {

// A registered kind for the length of a test.
class TestKind {
 public:
  explicit TestKind(AllocatorKind kind) : name_(kind.name) { allocator_registry().add(std::move(kind)); }
  ~TestKind() { allocator_registry().remove(name_); }
  TestKind(const TestKind&) = delete;
  TestKind& operator=(const TestKind&) = delete;

 private:
  std::string name_;
};

// round-robin under another name, with one parameter of its own; records the value it got.
AllocatorKind knob_kind(double* seen) {
  return {.name = "test-knob",
          .summary = "round-robin with a knob, for tests",
          .capabilities = {Capability::stationary},
          .parameters = {Parameter::real("test-knob-level", 0.25, 0, 1, "how far the test knob is turned")},
          .make = [seen](const Mdp& mdp, const ParameterReader& parameters) -> AllocatorFactory {
            *seen = parameters.real("test-knob-level");
            return [count = mdp.skeleton_count()] { return std::make_unique<RoundRobinAllocator>(count); };
          }};
}

std::string help_of(const std::string& command) {
  const auto app = cli::make_app();
  return app->get_subcommand(command)->help();
}

TEST(CliRegistry, ATestKindsParameterAppearsInHelpAndIsPassedThrough) {
  EXPECT_EQ(help_of("evaluate").find("--test-knob-level"), std::string::npos);
  double seen = -1;
  const TestKind added(knob_kind(&seen));
  for (const std::string command : {"evaluate", "table"}) {
    const std::string help = help_of(command);
    EXPECT_NE(help.find("--test-knob-level"), std::string::npos) << command << help;
    EXPECT_NE(help.find("test-knob: how far the test knob is turned (default 0.25)"), std::string::npos) << help;
  }
  EXPECT_NE(help_of("evaluate").find("test-knob"), std::string::npos);  // listed as a --solver

  const auto app = cli::make_app();
  const std::string instance = testing::source_path("data/instances/paper/figure1.json").string();
  app->parse("evaluate " + instance + " --solver test-knob --episodes 10 --test-knob-level 0.75", false);
  EXPECT_DOUBLE_EQ(seen, 0.75);

  const auto bad = cli::make_app();
  try {
    bad->parse("evaluate " + instance + " --solver test-knob --episodes 10 --test-knob-level 2", false);
    FAIL() << "expected UsageError";
  } catch (const UsageError& error) {
    EXPECT_STREQ(error.what(), "--test-knob-level: must be a finite number in [0, 1] (got '2')");
  }
}

TEST(CliRegistry, EveryCommandAndStudyHasHelp) {
  const auto app = cli::make_app();
  std::vector<std::vector<std::string>> commands;
  for (const CLI::App* command : app->get_subcommands({})) {
    commands.push_back({command->get_name()});
    for (const CLI::App* sub : command->get_subcommands({})) commands.push_back({command->get_name(), sub->get_name()});
  }
  EXPECT_GE(commands.size(), 16U);  // 13 commands and 3 studies
  for (std::vector<std::string> arguments : commands) {
    arguments.insert(arguments.begin(), ONTIME_CLI);
    arguments.emplace_back("--help");
    const auto result = testing::run_process(arguments);
    EXPECT_EQ(result.exit_code, 0) << arguments[1];
    EXPECT_NE(result.out.find("--help"), std::string::npos) << arguments[1];
  }
}

TEST(CliRegistry, AParameterGivenOncePerInstanceReachesEachInstanceWithExactParts) {
  const std::string one = testing::source_path("data/instances/paper/instance1.json").string();
  const std::string four = testing::source_path("data/instances/paper/instance4.json").string();
  const auto result = testing::run_process({ONTIME_CLI, "table", one, four, "--solvers", "dp,mcts", "--episodes", "20",
                                            "--iterations", "30", "--iterations", "40", "--exact", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto wrong = testing::run_process({ONTIME_CLI, "table", one, four, "--solvers", "dp", "--episodes", "20",
                                           "--iterations", "30", "--iterations", "40", "--iterations", "50"});
  EXPECT_EQ(wrong.exit_code, 2);
  EXPECT_NE(wrong.err.find("--iterations: give one value, or one per instance (3 given for 2 instances)"),
            std::string::npos)
      << wrong.err;
}

TEST(CliRegistry, TheRegistryRefusesContradictoryDeclarations) {
  double seen = 0;
  const TestKind added(knob_kind(&seen));
  AllocatorKind twin = knob_kind(&seen);
  EXPECT_THROW(allocator_registry().add(twin), UsageError);  // the name is taken
  twin.name = "test-knob-twin";
  twin.parameters[0].default_value = "0.5";  // same parameter, other default
  EXPECT_THROW(allocator_registry().add(twin), UsageError);
}

TEST(CliRegistry, DocsListEveryAllocatorAndParameter) {
  // docs/cli.md holds `ontime allocators` between two markers; a new kind or parameter must
  // be documented there (paste the command's output).
  std::ifstream file(testing::source_path("docs/cli.md"));
  std::stringstream text;
  text << file.rdbuf();
  const std::string docs = text.str();
  const std::string begin = "<!-- ontime allocators: begin -->\n";
  const std::string end = "<!-- ontime allocators: end -->";
  const auto from = docs.find(begin);
  const auto to = docs.find(end);
  ASSERT_NE(from, std::string::npos);
  ASSERT_NE(to, std::string::npos);
  EXPECT_EQ(docs.substr(from + begin.size(), to - from - begin.size()), "\n" + cli::allocators_markdown() + "\n");
}

}  // namespace
}  // namespace ontime
