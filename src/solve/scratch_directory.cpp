#include "solve/scratch_directory.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <pthread.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <string>
#include <string_view>
#include <system_error>

#include "ontime/util/error.hpp"
#include "util/signal_handoff.hpp"

namespace ontime {
namespace {

constexpr std::string_view kPrefix = "ontime-layers-";
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};
constexpr std::size_t kSlots = 64;  // directories alive at once in one process (ranks played by threads)
constexpr std::size_t kMaxPath = 4096;

std::string host_name() {
  std::array<char, 256> name{};
  if (::gethostname(name.data(), name.size() - 1) != 0 || name[0] == '\0') return "localhost";
  std::string host(name.data());
  // One path component, whatever the host is called.
  for (char& c : host) {
    if (c == '/') c = '_';
  }
  return host;
}

// ---- the signal handler's table: plain fixed buffers, published under the registry's mutex
// with the signals blocked, read by the handler ----
struct Slot {
  std::atomic<bool> used{false};
  char path[kMaxPath]{};
};
Slot slots[kSlots];
std::mutex registry;
int handler_users = 0;  // directories with remove_on_signal alive
struct sigaction previous_actions[std::size(kSignals)];
std::atomic<int> handling{0};

// Removes every entry of a directory of plain files, then the directory (async-signal-safe:
// open, getdents64, unlinkat, close, rmdir). Solver threads may still be writing as the handler
// runs, so a file made meanwhile is caught by the next round.
void remove_flat_directory(const char* path) {
  for (int round = 0; round < 4; ++round) {
    const int directory = ::open(path, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (directory < 0) return;
    alignas(8) char buffer[8192];
    for (;;) {
      const long bytes = ::syscall(SYS_getdents64, directory, buffer, sizeof buffer);
      if (bytes <= 0) break;
      for (long at = 0; at < bytes;) {
        const auto* entry = reinterpret_cast<const struct dirent64*>(buffer + at);
        const char* name = entry->d_name;
        if (!(name[0] == '.' && (name[1] == '\0' || (name[1] == '.' && name[2] == '\0')))) {
          ::unlinkat(directory, name, 0);
        }
        at += entry->d_reclen;
      }
    }
    ::close(directory);
    if (::rmdir(path) == 0 || errno != ENOTEMPTY) return;
  }
}

void write_text(const char* text) {
  std::size_t left = std::strlen(text);
  while (left > 0) {
    const ssize_t written = ::write(STDERR_FILENO, text, left);
    if (written <= 0) return;
    text += written;
    left -= static_cast<std::size_t>(written);
  }
}

const char* signal_name(int signal_number) {
  switch (signal_number) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    default:
      return "a signal";
  }
}

extern "C" void remove_scratch_and_end(int signal_number) {
  if (handling.exchange(1) == 0) {  // a second signal meanwhile (another thread) ends below
    for (Slot& slot : slots) {
      if (!slot.used.load()) continue;
      remove_flat_directory(slot.path);
      write_text("ontime: ");
      write_text(signal_name(signal_number));
      write_text(": stopped; removed the scratch directory ");
      write_text(slot.path);
      write_text("\n");
    }
  }
  // The signal takes its course: the handler that was there before (e.g. OutputSet's, which
  // removes staged outputs and ends the process), else death by the signal.
  detail::hand_signal_on(signal_number, kSignals, previous_actions, std::size(kSignals));
}

sigset_t signal_set() {
  sigset_t set;
  sigemptyset(&set);
  for (const int signal_number : kSignals) sigaddset(&set, signal_number);
  return set;
}

int register_for_signals(const std::filesystem::path& path) {
  const std::string text = path.string();
  if (text.size() >= kMaxPath) return -1;
  const std::lock_guard lock(registry);
  const sigset_t blocked = signal_set();
  sigset_t previous;
  ::pthread_sigmask(SIG_BLOCK, &blocked, &previous);
  int slot = -1;
  for (std::size_t i = 0; i < kSlots; ++i) {
    if (!slots[i].used.load()) {
      std::memcpy(slots[i].path, text.c_str(), text.size() + 1);
      slots[i].used.store(true);
      slot = static_cast<int>(i);
      break;
    }
  }
  if (slot >= 0 && handler_users++ == 0) {
    struct sigaction action {};
    action.sa_handler = remove_scratch_and_end;
    action.sa_mask = blocked;  // one termination signal at a time
    for (std::size_t i = 0; i < std::size(kSignals); ++i) {
      ::sigaction(kSignals[i], nullptr, &previous_actions[i]);
      // A signal ignored (nohup, a launcher's choice) stays ignored.
      if (previous_actions[i].sa_handler != SIG_IGN) ::sigaction(kSignals[i], &action, nullptr);
    }
  }
  ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  return slot;
}

void unregister(int slot) {
  const std::lock_guard lock(registry);
  const sigset_t blocked = signal_set();
  sigset_t previous;
  ::pthread_sigmask(SIG_BLOCK, &blocked, &previous);
  slots[slot].used.store(false);
  if (--handler_users == 0) {
    for (std::size_t i = 0; i < std::size(kSignals); ++i) {
      if (previous_actions[i].sa_handler != SIG_IGN) ::sigaction(kSignals[i], &previous_actions[i], nullptr);
    }
  }
  ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
}

// HOST-PID-rankR-XXXXXX after the prefix: the host and the process, read from the right (a host
// name may hold dashes). False for anything else.
bool parse_name(std::string_view name, std::string& host, long& pid) {
  if (name.substr(0, kPrefix.size()) != kPrefix) return false;
  name.remove_prefix(kPrefix.size());
  const auto cut = [&name]() -> std::string_view {
    const std::size_t dash = name.rfind('-');
    if (dash == std::string_view::npos) return {};
    const std::string_view last = name.substr(dash + 1);
    name = name.substr(0, dash);
    return last;
  };
  const std::string_view random = cut();
  const std::string_view rank = cut();
  const std::string_view process = cut();
  if (random.size() != 6 || rank.substr(0, 4) != "rank" || process.empty() || name.empty()) return false;
  pid = 0;
  for (const char c : process) {
    if (c < '0' || c > '9' || pid > 1'000'000'000) return false;
    pid = pid * 10 + (c - '0');
  }
  host = std::string(name);
  return pid > 0;
}

std::uint64_t bytes_in(const std::filesystem::path& directory) {
  std::uint64_t bytes = 0;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(directory, error)) {
    std::error_code ignored;
    if (entry.is_regular_file(ignored)) bytes += entry.file_size(ignored);
  }
  return bytes;
}

// A process exists and has not ended: kill(pid, 0) finds it (a process we may not signal exists
// too) and it is not a zombie waiting to be reaped (its files are no longer written).
bool process_alive(long pid) {
  if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) return false;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  if (!std::getline(stat, text)) return true;
  const std::size_t name_end = text.rfind(')');  // the command name may hold spaces and parentheses
  return name_end == std::string::npos || name_end + 2 >= text.size() || text[name_end + 2] != 'Z';
}

}  // namespace

int remove_stale_scratch(const std::filesystem::path& folder, const ScratchDirectory::StaleNotice& notice) {
  const std::string host = host_name();
  int removed = 0;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    std::string entry_host;
    long pid = 0;
    std::error_code ignored;
    if (!entry.is_directory(ignored) || !parse_name(entry.path().filename().string(), entry_host, pid)) continue;
    // Only this host's processes can be seen; a process that exists (ours included, or one we may
    // not signal) is alive.
    if (entry_host != host || process_alive(pid)) continue;
    const std::uint64_t bytes = bytes_in(entry.path());
    std::filesystem::remove_all(entry.path(), ignored);
    if (ignored) continue;
    ++removed;
    if (notice) notice(entry.path(), bytes);
  }
  return removed;
}

ScratchDirectory::ScratchDirectory(const std::filesystem::path& parent_or_empty, int rank, bool remove_on_signal,
                                   const StaleNotice& notice) {
  std::error_code error;
  const std::filesystem::path parent =
      parent_or_empty.empty() ? std::filesystem::temp_directory_path(error) : parent_or_empty;
  if (!error) remove_stale_scratch(parent, notice);
  std::string pattern = (parent / (std::string(kPrefix) + host_name() + "-" + std::to_string(::getpid()) + "-rank" +
                                   std::to_string(rank) + "-XXXXXX"))
                            .string();
  if (error || ::mkdtemp(pattern.data()) == nullptr) {
    throw UsageError("cannot make a scratch directory for the layers in " + parent.string() +
                     " (choose another with --scratch)");
  }
  path_ = pattern;
  if (remove_on_signal) slot_ = register_for_signals(path_);
}

ScratchDirectory::~ScratchDirectory() {
  if (slot_ >= 0) unregister(slot_);
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

}  // namespace ontime
