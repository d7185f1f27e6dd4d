#include "ontime/util/output_set.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"

namespace ontime {
namespace {

constexpr int kTerminationSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
constexpr std::size_t kMaxMembers = 8;
constexpr std::size_t kMaxPath = 4096;

// What the signal handler removes: the staged files, then the staging directory. Plain arrays
// filled before the handler is installed, since a handler may only make async-signal-safe calls.
char staged_paths[kMaxMembers + 1][kMaxPath];
std::size_t staged_count = 0;  // the last entry is the directory
struct sigaction previous_actions[std::size(kTerminationSignals)];

void check_length(const std::filesystem::path& path) {
  if (path.string().size() >= kMaxPath) throw UsageError(path.string() + ": path too long for an output file");
}

void copy_path(char* slot, const std::filesystem::path& path) {
  const std::string text = path.string();
  std::memcpy(slot, text.c_str(), text.size() + 1);
}

// Writes `content` to `path` (a new file in the staging directory, which nobody else reads
// until the commit: no temporary of its own, so the directory holds only members).
void write_whole_file(const std::filesystem::path& path, std::string_view content) {
  const int descriptor = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (descriptor < 0) throw_file_error(path, "cannot create", errno);
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t written = ::write(descriptor, data, left);
    if (written < 0 && errno == EINTR) continue;
    if (written < 0) {
      const int error = errno;
      ::close(descriptor);
      throw_file_error(path, "cannot write", error);
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  const bool flushed = ::fsync(descriptor) == 0;
  const int flush_error = errno;
  if (::close(descriptor) != 0 || !flushed) throw_file_error(path, "cannot flush", flushed ? errno : flush_error);
}

extern "C" void remove_staging_and_end(int signal_number) {
  for (std::size_t i = 0; i + 1 < staged_count; ++i) ::unlink(staged_paths[i]);
  // Only members are ever written into the directory, so it is empty now (unless a producer
  // still running, such as a plotting child, has just created its file: then it stays, hidden).
  if (staged_count > 0) ::rmdir(staged_paths[staged_count - 1]);
  ::signal(signal_number, SIG_DFL);
  ::raise(signal_number);
}

sigset_t termination_set() {
  sigset_t set;
  sigemptyset(&set);
  for (const int signal_number : kTerminationSignals) sigaddset(&set, signal_number);
  return set;
}

// Rebuilds the handler's list: the staged members, then the directory (last).
void publish(const std::vector<std::filesystem::path>& members, const std::filesystem::path& staging) {
  check_length(staging);
  for (const std::filesystem::path& member : members) check_length(staging / member.filename());
  const sigset_t blocked = termination_set();
  sigset_t previous;
  ::pthread_sigmask(SIG_BLOCK, &blocked, &previous);
  staged_count = 0;
  for (const std::filesystem::path& member : members) {
    copy_path(staged_paths[staged_count++], staging / member.filename());
  }
  copy_path(staged_paths[staged_count++], staging);
  ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
}

}  // namespace

OutputSet::OutputSet(const std::filesystem::path& directory) : directory_(directory.empty() ? "." : directory) {
  std::string pattern = (directory_ / ".ontime-output-XXXXXX").string();
  check_length(pattern);
  // The termination signals wait until the handler that removes the directory is in place: one
  // that came between the directory's creation and the handler would leave it behind.
  const sigset_t blocked = termination_set();
  sigset_t previous_mask;
  ::pthread_sigmask(SIG_BLOCK, &blocked, &previous_mask);
  if (::mkdtemp(pattern.data()) == nullptr) {
    const int error = errno;
    ::pthread_sigmask(SIG_SETMASK, &previous_mask, nullptr);
    throw_file_error(directory_, "cannot create a staging directory", error);
  }
  staging_ = pattern;
  publish(members_, staging_);
  struct sigaction action {};
  action.sa_handler = remove_staging_and_end;
  sigemptyset(&action.sa_mask);
  for (std::size_t i = 0; i < std::size(kTerminationSignals); ++i) {
    ::sigaction(kTerminationSignals[i], &action, &previous_actions[i]);
  }
  ::pthread_sigmask(SIG_SETMASK, &previous_mask, nullptr);
}

OutputSet::~OutputSet() {
  // Likewise: a signal between the handlers' removal and the directory's would leave it behind.
  const sigset_t blocked = termination_set();
  sigset_t previous_mask;
  ::pthread_sigmask(SIG_BLOCK, &blocked, &previous_mask);
  for (std::size_t i = 0; i < std::size(kTerminationSignals); ++i) {
    ::sigaction(kTerminationSignals[i], &previous_actions[i], nullptr);
  }
  staged_count = 0;
  if (!committed_) {
    std::error_code ignored;
    std::filesystem::remove_all(staging_, ignored);
  }
  ::pthread_sigmask(SIG_SETMASK, &previous_mask, nullptr);
}

std::filesystem::path OutputSet::stage(const std::filesystem::path& target) {
  if (members_.size() + removals_.size() >= kMaxMembers) throw std::logic_error("an output set holds at most 8 files");
  members_.push_back(target);
  publish(members_, staging_);
  return staging_ / target.filename();
}

std::filesystem::path OutputSet::write(const std::filesystem::path& target, std::string_view content) {
  std::filesystem::path staged = stage(target);
  write_whole_file(staged, content);
  return staged;
}

void OutputSet::remove_on_commit(const std::filesystem::path& target) {
  if (members_.size() + removals_.size() >= kMaxMembers) throw std::logic_error("an output set holds at most 8 files");
  removals_.push_back(target);
}

void OutputSet::commit() {
  for (const std::filesystem::path& member : members_) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(staging_ / member.filename(), error)) {
      throw std::runtime_error(member.string() + ": was not produced");
    }
  }
  const sigset_t blocked = termination_set();
  sigset_t previous;
  ::pthread_sigmask(SIG_BLOCK, &blocked, &previous);
  const auto fail = [&](const std::filesystem::path& path, const char* what) {
    const int error = errno;
    ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    throw_file_error(path, what, error);
  };
  for (const std::filesystem::path& member : members_) {
    if (std::rename((staging_ / member.filename()).c_str(), member.c_str()) != 0) fail(member, "cannot replace");
  }
  for (const std::filesystem::path& stale : removals_) {
    if (::unlink(stale.c_str()) != 0 && errno != ENOENT) fail(stale, "cannot remove");
  }
  ::rmdir(staging_.c_str());
  committed_ = true;
  // The handlers go before the signals come back: a signal that arrived during the commit now
  // ends the process the ordinary way, with the new set complete.
  for (std::size_t i = 0; i < std::size(kTerminationSignals); ++i) {
    ::sigaction(kTerminationSignals[i], &previous_actions[i], nullptr);
  }
  staged_count = 0;
  ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
}

}  // namespace ontime
