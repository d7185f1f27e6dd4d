#include "ontime/util/atomic_file.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path directory = fs::temp_directory_path() / ("ontime_atomic_file_test_" + name);
  fs::remove_all(directory);
  fs::create_directories(directory);
  return directory;
}

std::string text_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::size_t entry_count(const fs::path& directory) {
  std::size_t count = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(directory)) ++count;
  return count;
}

// The message of the UsageError `write` throws (empty, and a test failure, for anything else).
template <class Write>
std::string usage_error_of(Write write) {
  try {
    write();
  } catch (const UsageError& error) {
    return error.what();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "not a UsageError: " << error.what();
    return "";
  }
  ADD_FAILURE() << "nothing thrown";
  return "";
}

TEST(AtomicFile, ReplacesARegularFileWhole) {
  const fs::path directory = scratch("regular");
  const fs::path file = directory / "out.txt";
  std::ofstream(file) << "old content, longer than the new";
  write_file_atomically(file, "new");
  EXPECT_EQ(text_of(file), "new");
  EXPECT_EQ(entry_count(directory), 1U);  // no temporary file left
}

TEST(AtomicFile, AWriterPutsItsPiecesInPlaceOnlyOnCommit) {
  const fs::path directory = scratch("pieces");
  const fs::path file = directory / "out.txt";
  std::ofstream(file) << "old";
  {
    AtomicFileWriter abandoned(file);
    abandoned.write("never ");
    abandoned.write("committed");
    EXPECT_EQ(entry_count(directory), 2U);  // the target and the temporary file
  }
  EXPECT_EQ(text_of(file), "old");
  EXPECT_EQ(entry_count(directory), 1U);
  AtomicFileWriter writer(file);
  writer.write("new ");
  writer.write("content");
  EXPECT_EQ(text_of(file), "old");
  writer.commit();
  EXPECT_EQ(text_of(file), "new content");
  EXPECT_EQ(entry_count(directory), 1U);
}

TEST(AtomicFile, AFolderThatCannotTakeTheFileIsTheCallersError) {
  const fs::path directory = scratch("folder");
  const fs::path missing = directory / "missing" / "out.txt";
  const std::string message = usage_error_of([&] { write_file_atomically(missing, "x"); });
  EXPECT_EQ(message.rfind(missing.string() + ": cannot create a temporary file beside it: ", 0), 0U) << message;
  EXPECT_NE(message.find("No such file or directory"), std::string::npos) << message;
  std::ofstream(directory / "file") << "x";
  EXPECT_NE(usage_error_of([&] { write_file_atomically(directory / "file" / "out.txt", "x"); }).find("Not a directory"),
            std::string::npos);
  fs::create_directory(directory / "sub");
  const std::string onto_directory = usage_error_of([&] { write_file_atomically(directory / "sub", "x"); });
  EXPECT_EQ(onto_directory, (directory / "sub").string() + ": cannot replace: Is a directory");
  EXPECT_TRUE(fs::is_directory(directory / "sub"));
  EXPECT_EQ(entry_count(directory), 2U);  // "file" and "sub" only
}

TEST(AtomicFile, AFifoIsWrittenDirectlyAndStaysAFifo) {
  const fs::path directory = scratch("fifo");
  const fs::path fifo = directory / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  write_file_atomically(fifo, "through the pipe");
  char buffer[64] = {};
  const ssize_t received = ::read(reader, buffer, sizeof buffer);
  ::close(reader);
  ASSERT_GT(received, 0);
  EXPECT_EQ(std::string(buffer, static_cast<std::size_t>(received)), "through the pipe");
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(entry_count(directory), 1U);
}

// Needs root (mknod): copies of /dev/null and /dev/full in a scratch folder stay character devices.
TEST(AtomicFile, ACharacterDeviceIsWrittenDirectlyAndStaysADevice) {
  if (::geteuid() != 0) GTEST_SKIP() << "creating a device node needs root";
  const fs::path directory = scratch("device");
  const fs::path device = directory / "null";
  ASSERT_EQ(::mknod(device.c_str(), S_IFCHR | 0666, ::makedev(1, 3)), 0);
  write_file_atomically(device, "discarded");
  EXPECT_TRUE(fs::is_character_file(device));
  // A copy of /dev/full: every write fails for want of space, which is the user's to fix.
  const fs::path full = directory / "full";
  ASSERT_EQ(::mknod(full.c_str(), S_IFCHR | 0666, ::makedev(1, 7)), 0);
  try {
    write_file_atomically(full, "no room");
    ADD_FAILURE() << "nothing thrown";
  } catch (const ResourceLimitError& error) {
    EXPECT_EQ(std::string(error.what()), full.string() + ": cannot write: No space left on device");
  }
  EXPECT_TRUE(fs::is_character_file(full));
  EXPECT_EQ(entry_count(directory), 2U);
}

TEST(AtomicFile, ASymbolicLinkIsFollowed) {
  const fs::path directory = scratch("link");
  const fs::path target = directory / "target.txt";
  const fs::path link = directory / "link.txt";
  std::ofstream(target) << "old";
  fs::create_symlink(target, link);
  write_file_atomically(link, "new");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(text_of(target), "new");
  EXPECT_EQ(entry_count(directory), 2U);
  const fs::path dangling = directory / "dangling.txt";
  fs::create_symlink(directory / "nothing.txt", dangling);
  EXPECT_NE(usage_error_of([&] { write_file_atomically(dangling, "x"); }).find("symbolic link"), std::string::npos);
  EXPECT_FALSE(fs::exists(directory / "nothing.txt"));
}

// A termination signal while a file is being written: with remove_temporaries_on_signal, the
// temporary file is removed and the process ends by the signal; the target stays as it was.
// Each case in a child process (the handlers and the death are process-wide).
TEST(AtomicFile, ATerminationSignalRemovesTheTemporaryFiles) {
  for (const int signal_number : {SIGTERM, SIGINT, SIGHUP}) {
    for (const bool enabled : {true, false}) {
      const fs::path directory = scratch("signal-" + std::to_string(signal_number) + (enabled ? "-on" : "-off"));
      std::ofstream(directory / "kept.txt") << "old";
      const pid_t child = ::fork();
      ASSERT_GE(child, 0);
      if (child == 0) {
        remove_temporaries_on_signal(enabled);
        AtomicFileWriter kept(directory / "kept.txt");
        AtomicFileWriter fresh(directory / "fresh.txt");
        kept.write("half of the new");
        fresh.write("half");
        ::kill(::getpid(), signal_number);
        ::_exit(0);  // not reached: the signal ends the process
      }
      int status = 0;
      ASSERT_EQ(::waitpid(child, &status, 0), child);
      ASSERT_TRUE(WIFSIGNALED(status)) << status;
      EXPECT_EQ(WTERMSIG(status), signal_number);
      EXPECT_EQ(text_of(directory / "kept.txt"), "old");
      // Without the switch (a Python interpreter's case) the two temporary files stay: what the
      // handlers remove.
      EXPECT_EQ(entry_count(directory), enabled ? 1U : 3U) << signal_number;
    }
  }
}

}  // namespace
}  // namespace ontime
