#pragma once
// The check every command that writes files makes before its work starts: each output can be
// written where it is asked for, is not a directory, is not one of the command's inputs (the
// same file, compared by device and inode, so a second name or a link is caught too) and is
// not another output of the same command. A failure is a UsageError naming the option and the
// path, so a bad path costs the user a second, not a training or a collection.

#include <filesystem>
#include <string>
#include <vector>

namespace ontime::cli {

// One file a command will write, and the option it comes from as the user should read it
// ("--out", or "--out (learning curve)" for a file written beside the one named).
struct OutputFile {
  std::string option;
  std::filesystem::path path;
};

// What to do about an output's folder that does not exist.
enum class MissingFolder {
  refuse,  // the folder must exist (commands writing one named file)
  create,  // created here, with its parents (commands documented to create them)
};

// Throws UsageError when an output is a directory, a dangling symbolic link, a block device or
// socket, an input, or another output; when its folder does not exist (MissingFolder::refuse)
// or cannot be created (MissingFolder::create), is not a folder or is not writable; or when an
// existing character device or FIFO is not writable (those are written directly, not replaced).
// Inputs that do not exist are skipped: reading them reports that.
void check_outputs(const std::vector<OutputFile>& outputs, const std::vector<std::filesystem::path>& inputs,
                   MissingFolder missing_folder = MissingFolder::refuse);

}  // namespace ontime::cli
