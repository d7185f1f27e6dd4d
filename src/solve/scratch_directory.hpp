#pragma once
// Internal: the private directory of one rank's layer files in the layered solver, and what
// keeps such directories from filling a disk when a run does not end normally.
//
// Name: ontime-layers-HOST-PID-rankR-XXXXXX inside the chosen folder. Removed with everything
// in it when the solve ends, by return or by exception. Two more promises:
// - When a run was killed (SIGKILL, a crash, a node lost), its directory stays; the next solve
//   over the same folder removes every such directory whose host is this one and whose process
//   is gone (never one of a live process, and never one of another host, whose processes cannot
//   be seen from here), and reports each.
// - With remove_on_signal, SIGINT, SIGTERM and SIGHUP remove the directories of every solve in
//   the process, write one line per directory to standard error, then let the signal take its
//   course (the handler that was there before, or death by the signal). Async-signal-safe: the
//   handler lists the directory with getdents64 and unlinks, with the paths kept in fixed
//   buffers filled before it is installed. Off by default, so that a host program's own
//   handlers (Python's, for KeyboardInterrupt) stay as they are.

#include <cstdint>
#include <filesystem>
#include <functional>

namespace ontime {

class ScratchDirectory {
 public:
  // Called for each directory of a gone process removed before this one was made: its path and
  // the bytes it held.
  using StaleNotice = std::function<void(const std::filesystem::path&, std::uint64_t bytes)>;

  // Makes the directory in `parent_or_empty` (empty: the system's temporary directory). Throws
  // UsageError when it cannot be made.
  ScratchDirectory(const std::filesystem::path& parent_or_empty, int rank, bool remove_on_signal,
                   const StaleNotice& notice);
  ~ScratchDirectory();
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;

  const std::filesystem::path& path() const noexcept { return path_; }
  std::filesystem::path file(int t, const char* what) const {
    return path_ / ("layer-" + std::to_string(t) + "." + what);
  }

 private:
  std::filesystem::path path_;
  int slot_ = -1;  // in the signal handler's table, when remove_on_signal
};

// Removes the scratch directories in `folder` left by processes of this host that are gone;
// returns how many. (Done by every ScratchDirectory; exposed for tests.)
int remove_stale_scratch(const std::filesystem::path& folder, const ScratchDirectory::StaleNotice& notice);

}  // namespace ontime
