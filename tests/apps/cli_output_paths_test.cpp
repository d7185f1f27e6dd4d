// CLI tests of the outputs every command writes, checked before any work: missing folders,
// directories in the way and outputs that are inputs refused; special files and links.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "apps/cli_test_support.hpp"

namespace ontime {
namespace {

using namespace cli_test;

// Every file a command writes is checked before its work starts: a missing or unusable folder,
// a directory in the way and an output that is one of the inputs (by identity: a hard link or
// a symbolic link to it too) are usage errors, exit 2, one line naming the option and the path,
// and nothing is written.
class OutputPaths : public ::testing::Test {
 protected:
  void SetUp() override {
    // A folder per test: ctest runs the tests of this fixture in parallel.
    dir = scratch(std::string("outputs_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    instance = (dir / "instance.json").string();
    std::filesystem::copy_file(paper("figure1"), instance);
    log = (dir / "figure1.jsonl").string();
    ASSERT_EQ(ontime({"sample-log", instance, "--attempts", "10", "-o", log}).exit_code, 0);
    std::filesystem::create_directory(dir / "folder");
    std::ofstream(dir / "file") << "not a folder";
  }

  // Runs the command, which must fail at once with the option and the path named, and checks
  // that the scratch folder holds what it held before (no output, no temporary file).
  void expect_refused(const std::vector<std::string>& arguments, const std::string& option, const std::string& path,
                      const std::string& reason) {
    const std::vector<std::filesystem::path> before = entries();
    const auto result = ontime(arguments);
    EXPECT_EQ(result.exit_code, 2) << arguments[0] << " " << option << " " << path << ": " << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_NE(result.err.find("usage error: " + option + ": " + path + ": "), std::string::npos) << result.err;
    EXPECT_NE(result.err.find(reason), std::string::npos) << result.err;
    EXPECT_EQ(entries(), before) << result.err;
  }

  std::vector<std::filesystem::path> entries() const {
    std::vector<std::filesystem::path> found;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) found.push_back(entry.path());
    std::sort(found.begin(), found.end());
    return found;
  }

  std::filesystem::path dir;
  std::string instance;
  std::string log;
};

TEST_F(OutputPaths, AnOutputInAMissingFolderIsRefused) {
  const std::string missing = (dir / "missing" / "out.json").string();
  const std::string folder = "cannot write into " + (dir / "missing").string() + " (no such folder)";
  expect_refused({"sample-log", instance, "-o", missing}, "--output", missing, folder);
  expect_refused({"fit", log, "--step", "1", "--deadline", "5", "--skeletons", instance, "-o", missing}, "--output",
                 missing, folder);
  expect_refused({"plot", instance, "-o", missing}, "--output", missing, folder);
  expect_refused({"reduce-knapsack", testing::source_path("data/knapsack/example.json").string(), "--out", missing},
                 "--out", missing, folder);
  expect_refused({"map", "--domain", "navigation", "-o", missing}, "--output", missing, folder);
  // train, study and collect create missing folders; one that cannot be created is refused.
  const std::string under_a_file = (dir / "file" / "out.json").string();
  const std::string not_a_folder = "cannot write into " + (dir / "file").string();
  expect_refused({"train", instance, "--out", under_a_file}, "--out", under_a_file, not_a_folder);
  expect_refused({"study", "anytime", instance, "--out", (dir / "file").string()}, "--out",
                 (dir / "file" / "anytime.csv").string(), not_a_folder);
  expect_refused(
      {"collect", "--domain", "navigation", "--trials", "1", "--log", (dir / "log.jsonl").string(), "-o", under_a_file},
      "--instance", under_a_file, not_a_folder);
}

TEST_F(OutputPaths, AnOutputOntoADirectoryIsRefused) {
  const std::string folder = (dir / "folder").string();
  expect_refused({"sample-log", instance, "-o", folder}, "--output", folder, "is a directory");
  expect_refused({"fit", log, "--step", "1", "--deadline", "5", "--skeletons", instance, "-o", folder}, "--output",
                 folder, "is a directory");
  expect_refused({"plot", instance, "-o", folder}, "--output", folder, "is a directory");
  expect_refused({"train", instance, "--out", folder}, "--out", folder, "is a directory");
  expect_refused(
      {"collect", "--domain", "navigation", "--trials", "1", "--log", folder, "-o", (dir / "out.json").string()},
      "--log", folder, "is a directory");
  std::filesystem::create_directory(dir / "study");
  std::filesystem::create_directory(dir / "study" / "anytime.csv");
  const std::string csv = (dir / "study" / "anytime.csv").string();
  expect_refused({"study", "anytime", instance, "--out", (dir / "study").string()}, "--out", csv, "is a directory");
}

TEST_F(OutputPaths, AnOutputThatIsAnInputIsRefused) {
  const std::string destroys = "writing it would destroy it";
  expect_refused({"sample-log", instance, "-o", instance}, "--output", instance, destroys);
  expect_refused({"train", instance, "--out", instance}, "--out", instance, destroys);
  expect_refused({"plot", instance, "-o", instance}, "--output", instance, destroys);
  expect_refused({"fit", log, "--step", "1", "--deadline", "5", "--skeletons", instance, "-o", log}, "--output", log,
                 destroys);
  expect_refused({"fit", log, "--step", "1", "--deadline", "5", "--skeletons", instance, "-o", instance}, "--output",
                 instance, destroys);
  // Another name for the same file: a hard link and a symbolic link.
  const std::string hard = (dir / "hard.json").string();
  std::filesystem::create_hard_link(instance, hard);
  expect_refused({"sample-log", instance, "-o", hard}, "--output", hard, destroys);
  const std::string symbolic = (dir / "symbolic.json").string();
  std::filesystem::create_symlink(instance, symbolic);
  expect_refused({"train", symbolic, "--out", instance}, "--out", instance, destroys);
  // A file written beside the one named, and the plotted data beside a PNG named .csv.
  const std::string curve = (dir / "policy.curve.csv").string();
  std::filesystem::copy_file(instance, curve);
  expect_refused({"train", curve, "--out", (dir / "policy.json").string()}, "--out (learning curve)", curve, destroys);
  const std::string data = (dir / "data.csv").string();
  expect_refused({"plot", instance, "-o", data}, "--output (plotted data)", data, "is also the output of --output");
  // study: an output inside --out that is one of the instances.
  std::filesystem::create_directory(dir / "study");
  const std::string csv = (dir / "study" / "anytime.csv").string();
  std::filesystem::create_symlink(instance, csv);
  expect_refused({"study", "anytime", instance, "--out", (dir / "study").string()}, "--out", csv, destroys);
  const std::string world = (dir / "world.json").string();
  std::filesystem::copy_file(testing::source_path("data/domains/navigation.json"), world);
  expect_refused({"collect", "--domain", "navigation", "--world", world, "--trials", "1", "--log", world, "-o",
                  (dir / "out.json").string()},
                 "--log", world, destroys);
}

// The check comes before the training: a training far too long to finish in the test's time
// returns at once with the early message, having written nothing.
TEST_F(OutputPaths, TrainingIsRefusedBeforeItStarts) {
  const std::string under_a_file = (dir / "file" / "policy.json").string();
  const std::vector<std::filesystem::path> before = entries();
  const auto result =
      testing::run_process({ONTIME_CLI, "train", instance, "--episodes", "1000000000", "--out", under_a_file}, 60'000);
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_EQ(result.err, "ontime: usage error: --out: " + under_a_file + ": cannot write into " +
                            (dir / "file").string() + " (not a folder)\n");
  EXPECT_EQ(entries(), before);
}

TEST_F(OutputPaths, SpecialFilesAreWrittenDirectlyAndLinksAreFollowed) {
  // A FIFO stays a FIFO and its reader gets the log. The read end is open before the command
  // runs (so that its open does not wait) and is read once it has finished (the log fits in
  // the pipe's buffer).
  const std::filesystem::path fifo = dir / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  const auto result = ontime({"sample-log", instance, "--attempts", "10", "-o", fifo.string()});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  std::string received;
  char buffer[4096];
  for (ssize_t n; (n = ::read(reader, buffer, sizeof buffer)) > 0;)
    received.append(buffer, static_cast<std::size_t>(n));
  ::close(reader);
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
  EXPECT_EQ(received, read_file(log));
  // A symbolic link is followed: the file it points to is replaced, the link stays a link.
  const std::filesystem::path target = dir / "target.jsonl";
  const std::filesystem::path link = dir / "link.jsonl";
  std::ofstream(target) << "old";
  std::filesystem::create_symlink(target, link);
  ASSERT_EQ(ontime({"sample-log", instance, "--attempts", "10", "-o", link.string()}).exit_code, 0);
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_EQ(read_file(target), read_file(log));
  // A link to nothing is refused.
  const std::filesystem::path dangling = dir / "dangling.jsonl";
  std::filesystem::create_symlink(dir / "nothing.jsonl", dangling);
  expect_refused({"sample-log", instance, "-o", dangling.string()}, "--output", dangling.string(),
                 "is a symbolic link to a missing file");
}

}  // namespace
}  // namespace ontime
