// CLI tests of `plot`: the histograms and their data, instances with huge ids and names, a
// signal while the Python child draws (no figure, the same signal), a failing script reported in
// one line, and a missing temporary folder.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "apps/cli_test_support.hpp"

namespace ontime {
namespace {

using namespace cli_test;

TEST(Cli, PlotWritesTheHistogramsAndTheirData) {
  const std::filesystem::path dir = scratch("plot");
  const std::string png = (dir / "figure1.png").string();
  const auto result = ontime({"plot", paper("figure1"), "-o", png});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(read_file(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const std::string csv = read_file(dir / "figure1.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "action,distribution,step,probability");
  EXPECT_NE(csv.find("\"d1\",planning,4,0.5\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\"d1\",execution,10,0.5\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\"d1\",planning,never,0\n"), std::string::npos) << csv;
  EXPECT_EQ(ontime({"plot", "/nonexistent.json"}).exit_code, 2);
}

// Instance 4 with its first action renamed to `id` and the instance renamed to `name`.
std::string instance4_renamed(const std::string& id, const std::string& name) {
  json instance = json::parse(read_file(paper("instance4")));
  instance["name"] = name;
  if (id != "a1_1") {
    instance["actions"][id] = instance["actions"]["a1_1"];
    instance["actions"].erase("a1_1");
    instance["skeletons"][0][0] = id;
  }
  return instance.dump();
}

// Valid instances whatever their ids and name: the labels are shortened for drawing (and their dollar
// signs escaped: matplotlib reads $...$ as mathematical notation), the data CSV keeps them whole.
TEST(Cli, PlotDrawsInstancesWithHugeIdsAndNames) {
  const std::filesystem::path dir = scratch("plot_long");
  const std::vector<std::pair<std::string, std::string>> cases{{std::string(65'536, 'a'), std::string(1'000'000, 'n')},
                                                               {std::string(1'000'000, 'b'), "short"},
                                                               {"a1_1", std::string(10'000'000, 'm')},
                                                               {"a$\\foo$", "cost $5 $\\nope$"}};
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string instance = (dir / ("long" + std::to_string(i) + ".json")).string();
    std::ofstream(instance) << instance4_renamed(cases[i].first, cases[i].second);
    const std::filesystem::path png = dir / ("long" + std::to_string(i) + ".png");
    const auto result = ontime({"plot", instance, "-o", png.string()});
    ASSERT_EQ(result.exit_code, 0) << result.err.substr(0, 2000);
    EXPECT_EQ(read_file(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    const std::string csv = read_file(std::filesystem::path(png).replace_extension(".csv"));
    EXPECT_NE(csv.find("\"" + cases[i].first + "\",planning,1,0.29999999999999999\n"), std::string::npos);
  }
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 3 * cases.size());  // instance, CSV and PNG: no temporary file left
}

// The pid of the process whose parent is `parent` and whose command line contains `word` (0 if none),
// with that command line (NUL-separated arguments).
std::pair<pid_t, std::vector<std::string>> child_running(pid_t parent, const std::string& word) {
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string stat = read_file(entry.path() / "stat");
    const std::size_t end_of_command = stat.rfind(')');
    if (end_of_command == std::string::npos) continue;
    std::istringstream fields(stat.substr(end_of_command + 1));
    std::string state;
    pid_t parent_pid = 0;
    fields >> state >> parent_pid;
    if (parent_pid != parent) continue;
    const std::string command_line = read_file(entry.path() / "cmdline");
    if (command_line.find(word) == std::string::npos) continue;
    std::vector<std::string> arguments;
    for (std::size_t start = 0; start < command_line.size();) {
      const std::size_t nul = std::min(command_line.find('\0', start), command_line.size());
      arguments.push_back(command_line.substr(start, nul - start));
      start = nul + 1;
    }
    return {static_cast<pid_t>(std::stol(name)), arguments};
  }
  return {0, {}};
}

// A signal sent to `ontime plot` while its Python child draws: the child is stopped and waited for,
// ontime dies of the same signal, and no figure appears, not even seconds later.
void expect_interrupted_plot_leaves_nothing(int signal_number) {
  const std::filesystem::path dir = scratch("plot_signal_" + std::to_string(signal_number));
  // 48 actions whose planning PMFs spread over 2,000 steps: seconds of drawing.
  json instance = json::parse(read_file(paper("instance4")));
  json pmf = json::object();
  for (int step = 1; step <= 2000; ++step) pmf[std::to_string(step)] = 1.0 / 2000;
  json actions = json::object();
  json skeletons = json::array();
  std::vector<std::string> ids;
  for (int k = 0; k < 48; ++k) {
    // Built with += : GCC 12 warns falsely (-Wrestrict) on "a" + std::string.
    std::string id(1, 'a');
    id += std::to_string(k);
    ids.push_back(id);
    actions[id] = {{"planning", {{"pmf", pmf}}}, {"execution", {{"pmf", {{"1", 1}}}}}};
    if (k < 16) skeletons.push_back(json::array({id}));
  }
  for (int k = 16; k < 48; ++k) skeletons[k % 16].push_back(ids[k]);
  instance["deadline"] = 2000;
  instance["actions"] = actions;
  instance["skeletons"] = skeletons;
  const std::string path = (dir / "slow.json").string();
  std::ofstream(path) << instance.dump();
  const std::filesystem::path png = dir / "slow.png";

  const pid_t ontime_pid = ::fork();
  ASSERT_GE(ontime_pid, 0);
  if (ontime_pid == 0) {
    const int nothing = ::open("/dev/null", O_WRONLY);
    ::dup2(nothing, STDOUT_FILENO);
    ::dup2(nothing, STDERR_FILENO);
    ::execl(ONTIME_CLI, ONTIME_CLI, "plot", path.c_str(), "-o", png.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  std::pair<pid_t, std::vector<std::string>> script{0, {}};
  int status = 0;
  bool exited = false;
  while (script.first == 0 && !exited) {
    script = child_running(ontime_pid, "plot_histograms.py");
    exited = ::waitpid(ontime_pid, &status, WNOHANG) == ontime_pid;
    if (script.first == 0 && !exited) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_FALSE(exited) << "ontime plot ended before its Python child was seen";
  ASSERT_EQ(::kill(ontime_pid, signal_number), 0);
  ASSERT_EQ(::waitpid(ontime_pid, &status, 0), ontime_pid);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number) << "status " << status;
  EXPECT_EQ(::kill(script.first, 0), -1) << "the Python child outlived ontime";
  EXPECT_EQ(errno, ESRCH);
  const auto output = std::find(script.second.begin(), script.second.end(), "--output");
  ASSERT_NE(output, script.second.end());
  ASSERT_NE(output + 1, script.second.end());
  const std::filesystem::path drawing(*(output + 1));
  std::this_thread::sleep_for(std::chrono::seconds(3));  // an orphaned child would have drawn by now
  EXPECT_FALSE(std::filesystem::exists(png));
  EXPECT_FALSE(std::filesystem::exists(drawing));
  EXPECT_FALSE(std::filesystem::exists(drawing.parent_path())) << "temporary directory left";
  if (::kill(script.first, 0) == 0) ::kill(script.first, SIGKILL);  // an orphan from a failed run
}

TEST(Cli, SigtermDuringAPlotStopsThePythonChildAndLeavesNoFigure) { expect_interrupted_plot_leaves_nothing(SIGTERM); }

TEST(Cli, SigintDuringAPlotStopsThePythonChildAndLeavesNoFigure) { expect_interrupted_plot_leaves_nothing(SIGINT); }

// A failing script is reported in one line, its last: exit 2 when it says the data is bad, 1 otherwise.
TEST(Cli, AFailingPlotScriptIsReportedInOneLine) {
  const std::filesystem::path dir = scratch("plot_failure");
  const auto plot_with = [&](const std::string& script) {
    const std::filesystem::path scripts = dir / "scripts";
    std::filesystem::create_directories(scripts);
    std::ofstream(scripts / "plot_histograms.py") << script;
    return testing::run_process({"/usr/bin/env", "ONTIME_PYTHON_DIR=" + scripts.string(), ONTIME_CLI, "plot",
                                 paper("figure1"), "-o", (dir / "figure1.png").string()});
  };
  const auto crashed = plot_with("import sys\nprint('drawing')\nraise RuntimeError('the drawing broke')\n");
  EXPECT_EQ(crashed.exit_code, 1);
  EXPECT_EQ(std::count(crashed.err.begin(), crashed.err.end(), '\n'), 1) << crashed.err;
  EXPECT_NE(crashed.err.find("RuntimeError: the drawing broke"), std::string::npos) << crashed.err;
  const auto refused = plot_with(
      "import sys\nsys.stderr.write('a warning\\nplot_histograms.py: the data is bad\\n')\n"
      "sys.exit(65)\n");
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  EXPECT_NE(refused.err.find("plot_histograms.py: the data is bad"), std::string::npos) << refused.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "figure1.png"));

  // The real script on bad data: one line, the bad-input status, no traceback.
  std::ofstream(dir / "bad.csv") << "action,distribution,step,probability\nx,planning,1,abc\n";
  const auto direct =
      testing::run_process({"/usr/bin/python3", testing::source_path("python/plot_histograms.py").string(), "--data",
                            (dir / "bad.csv").string(), "--output", (dir / "bad.png").string(), "--deadline", "4"});
  EXPECT_EQ(direct.exit_code, 65);
  EXPECT_EQ(direct.err, "plot_histograms.py: " + (dir / "bad.csv").string() +
                            ": row 1, column probability: 'abc' is not a number\n");
}

// The figure is drawn in a folder of $TMPDIR: without one, a usage error naming it, and no figure.
TEST(Cli, PlotWithoutATemporaryFolderIsAUsageError) {
  const std::filesystem::path dir = scratch("plot_tmpdir");
  for (const std::string& temporary : {std::string("/nonexistent"), (dir / "file").string()}) {
    std::ofstream(dir / "file") << "not a folder";
    const auto result = testing::run_process({"/usr/bin/env", "TMPDIR=" + temporary, ONTIME_CLI, "plot",
                                              paper("figure1"), "-o", (dir / "figure1.png").string()});
    EXPECT_EQ(result.exit_code, 2) << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_NE(result.err.find("($TMPDIR)"), std::string::npos) << result.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "figure1.png"));
  }
}

}  // namespace
}  // namespace ontime
