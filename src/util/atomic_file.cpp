#include "ontime/util/atomic_file.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <mutex>
#include <stdexcept>
#include <string>

#include "ontime/util/error.hpp"
#include "util/signal_handoff.hpp"

namespace ontime {
// The error type for a failed system call: the caller's to fix (a path, a permission, a full
// disk) or a failure of the system itself.
void throw_file_error(const std::filesystem::path& path, const char* what, int error) {
  const std::string message = path.string() + ": " + what + ": " + std::strerror(error);
  switch (error) {
    case EACCES:
    case EPERM:
    case ENOENT:
    case ENOTDIR:
    case EISDIR:
    case EROFS:
    case ENAMETOOLONG:
    case ELOOP:
    case ETXTBSY:
      throw UsageError(message);
    case ENOSPC:
    case EDQUOT:
    case EFBIG:
      throw ResourceLimitError(message);
    default:
      throw std::runtime_error(message);
  }
}

namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const char* what, int error) {
  throw_file_error(path, what, error);
}

// Writes all of `content` to `descriptor`; returns 0 or the errno of the failed write.
int write_all(int descriptor, std::string_view content) {
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t written = ::write(descriptor, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  return 0;
}

// ---- temporary files removed on a termination signal ----
// One table for every writer of the process: each temporary file's path in a fixed buffer,
// published under a mutex with the signals blocked, read by the handler (async-signal-safe:
// unlink only). The handlers are installed while a temporary file exists, and only once
// remove_temporaries_on_signal(true) (the command line; Python turns Ctrl-C into an exception,
// and the writer's destructor removes the file as the exception unwinds).
// (A namespace of its own: the library is compiled in batches, and output_set.cpp has a table too.)
namespace temporary_files {

constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
constexpr std::size_t kSlots = 64;  // temporary files at once; beyond, a file is not removed on a signal
constexpr std::size_t kMaxPath = 4096;

struct Slot {
  std::atomic<bool> used{false};
  char path[kMaxPath]{};
};
Slot slots[kSlots];
std::mutex registry;
bool enabled = false;
int users = 0;  // slots in use
struct sigaction previous_actions[std::size(kSignals)];

extern "C" void remove_temporaries_and_end(int signal_number) {
  for (Slot& slot : slots) {
    if (slot.used.load()) ::unlink(slot.path);
  }
  // The signal takes its course: the handler that was there before (another one's cleanup, which
  // ends the process in turn), else death by the signal.
  detail::hand_signal_on(signal_number, kSignals, previous_actions, std::size(kSignals));
}

// The termination signals blocked for the life of the object (so that a temporary file and its
// slot appear and disappear together).
class SignalsBlocked {
 public:
  SignalsBlocked() {
    sigset_t blocked;
    sigemptyset(&blocked);
    for (const int signal_number : kSignals) sigaddset(&blocked, signal_number);
    ::pthread_sigmask(SIG_BLOCK, &blocked, &previous_);
  }
  ~SignalsBlocked() { ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr); }
  SignalsBlocked(const SignalsBlocked&) = delete;
  SignalsBlocked& operator=(const SignalsBlocked&) = delete;

 private:
  sigset_t previous_{};
};

// Called with the signals blocked. -1 when not enabled, the path too long or the table full.
int register_temporary(const std::string& path) {
  const std::lock_guard lock(registry);
  if (!enabled || path.size() >= kMaxPath) return -1;
  for (std::size_t i = 0; i < kSlots; ++i) {
    if (slots[i].used.load()) continue;
    std::memcpy(slots[i].path, path.c_str(), path.size() + 1);
    slots[i].used.store(true);
    if (users++ == 0) {
      struct sigaction action {};
      action.sa_handler = remove_temporaries_and_end;
      sigemptyset(&action.sa_mask);
      for (const int signal_number : kSignals) sigaddset(&action.sa_mask, signal_number);  // one at a time
      for (std::size_t s = 0; s < std::size(kSignals); ++s) {
        ::sigaction(kSignals[s], nullptr, &previous_actions[s]);
        // A signal ignored (nohup, a launcher's choice) stays ignored.
        if (previous_actions[s].sa_handler != SIG_IGN) ::sigaction(kSignals[s], &action, nullptr);
      }
    }
    return static_cast<int>(i);
  }
  return -1;
}

// Called with the signals blocked.
void unregister_temporary(int slot) {
  if (slot < 0) return;
  const std::lock_guard lock(registry);
  slots[slot].used.store(false);
  if (--users == 0) {
    for (std::size_t s = 0; s < std::size(kSignals); ++s) {
      if (previous_actions[s].sa_handler != SIG_IGN) ::sigaction(kSignals[s], &previous_actions[s], nullptr);
    }
  }
}

}  // namespace temporary_files

}  // namespace

void remove_temporaries_on_signal(bool enable) {
  const std::lock_guard lock(temporary_files::registry);
  temporary_files::enabled = enable;
}

AtomicFileWriter::AtomicFileWriter(const std::filesystem::path& path) : target_(path) {
  struct stat link {};
  bool direct = false;
  if (::lstat(path.c_str(), &link) != 0) {
    if (errno != ENOENT) fail(path, "cannot inspect", errno);
  } else {
    struct stat target {};
    if (::stat(path.c_str(), &target) != 0) fail(path, "is a symbolic link that cannot be followed", errno);
    if (S_ISDIR(target.st_mode)) fail(path, "cannot replace", EISDIR);
    // Devices and FIFOs cannot be replaced without destroying them; they get the content directly.
    direct = S_ISCHR(target.st_mode) || S_ISFIFO(target.st_mode);
    if (!direct && !S_ISREG(target.st_mode)) {
      throw UsageError(path.string() + ": is neither a regular file, a character device nor a FIFO");
    }
    if (!direct && S_ISLNK(link.st_mode)) {
      std::error_code error;
      target_ = std::filesystem::canonical(path, error);
      if (error) fail(path, "cannot follow the symbolic link", error.value());
    }
  }
  if (direct) {
    descriptor_ = ::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (descriptor_ < 0) fail(path, "cannot open", errno);
    return;
  }
  const std::filesystem::path directory =
      target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
  // Built with += : GCC 12 warns falsely (-Wrestrict) on "." + std::string.
  std::string temporary_name(".");
  temporary_name += target_.filename().string();
  temporary_name += ".tmp-XXXXXX";
  temporary_ = (directory / temporary_name).string();
  const temporary_files::SignalsBlocked blocked;
  descriptor_ = ::mkstemp(temporary_.data());
  if (descriptor_ < 0) {
    temporary_.clear();
    fail(target_, "cannot create a temporary file beside it", errno);
  }
  slot_ = temporary_files::register_temporary(temporary_);
}

AtomicFileWriter::~AtomicFileWriter() {
  if (descriptor_ >= 0) ::close(descriptor_);
  const temporary_files::SignalsBlocked blocked;
  if (!committed_ && !temporary_.empty()) ::unlink(temporary_.c_str());
  temporary_files::unregister_temporary(slot_);
}

void AtomicFileWriter::write(std::string_view piece) {
  if (const int error = write_all(descriptor_, piece); error != 0) fail(target_, "cannot write", error);
}

void AtomicFileWriter::commit() {
  if (temporary_.empty()) {  // a device or FIFO: written already
    const int error = ::close(descriptor_) != 0 ? errno : 0;
    descriptor_ = -1;
    committed_ = true;
    if (error != 0) fail(target_, "cannot write", error);
    return;
  }
  if (::fchmod(descriptor_, 0644) != 0) fail(target_, "cannot set permissions", errno);
  if (::fsync(descriptor_) != 0) fail(target_, "cannot flush", errno);
  const int closed = ::close(descriptor_);
  descriptor_ = -1;
  if (closed != 0) fail(target_, "cannot close", errno);
  // Renamed and out of the table together: a signal between the two would remove nothing or the
  // name of a file no longer there.
  const temporary_files::SignalsBlocked blocked;
  if (std::rename(temporary_.c_str(), target_.c_str()) != 0) fail(target_, "cannot replace", errno);
  committed_ = true;
  temporary_files::unregister_temporary(slot_);
  slot_ = -1;
}

void write_file_atomically(const std::filesystem::path& path, std::string_view content) {
  AtomicFileWriter writer(path);
  writer.write(content);
  writer.commit();
}

}  // namespace ontime
