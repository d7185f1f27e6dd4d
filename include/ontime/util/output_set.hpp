#pragma once
// Writing the several files of one command's output (a policy, its learning curve CSV and PNG)
// so that they belong together: an interruption leaves either the complete old set or the
// complete new set, never a mix, and no temporary file.
//
// Every member is first written into a staging directory beside the targets (so that renames
// stay on one file system), under its final file name (so that a producer such as a plotting
// script sees the names it would see at the target). `commit` then renames the members over
// their targets and removes the targets this run does not produce (older members that no longer
// belong), with the termination signals (SIGINT, SIGTERM, SIGHUP, SIGQUIT) blocked and
// delivered only once the new set is complete. A termination signal during staging removes the
// staging directory before the process ends; an OutputSet destroyed without commit removes it too.
// Only SIGKILL or a power loss within the few renames of a commit can leave a mix.
//
// At most one OutputSet may exist at a time (its signal handlers are process-wide).

#include <filesystem>
#include <string_view>
#include <vector>

namespace ontime {

class OutputSet {
 public:
  // Every target lies in `directory` (which must exist). Throws as write_file_atomically does
  // (atomic_file.hpp: UsageError for a missing or unwritable directory or a path too long, naming
  // it and the system's reason) when the staging directory cannot be made.
  explicit OutputSet(const std::filesystem::path& directory);
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  // Makes `target` (a file name in the directory) a member and returns the path a producer
  // writes it to. At most 8 members and removals in all.
  std::filesystem::path stage(const std::filesystem::path& target);
  // Stages `target` with `content`; returns where (as stage does).
  std::filesystem::path write(const std::filesystem::path& target, std::string_view content);
  // `target` does not belong to this output: removed at commit if it exists.
  void remove_on_commit(const std::filesystem::path& target);
  // Renames every staged member over its target and removes the others. Throws
  // std::runtime_error (naming the file) when a member is missing, and as write_file_atomically
  // does when a rename fails.
  void commit();

 private:
  std::filesystem::path directory_;
  std::filesystem::path staging_;
  std::vector<std::filesystem::path> members_;  // targets, staged under the same file name
  std::vector<std::filesystem::path> removals_;
  bool committed_ = false;
};

}  // namespace ontime
