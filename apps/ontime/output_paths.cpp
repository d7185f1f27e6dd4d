#include "output_paths.hpp"

#include <unistd.h>

#include <system_error>

#include "ontime/util/error.hpp"

namespace ontime::cli {
namespace {

namespace fs = std::filesystem;

fs::path folder_of(const fs::path& path) { return path.has_parent_path() ? path.parent_path() : fs::path("."); }

// The path with links and dot components resolved as far as it exists, to compare outputs not yet written.
fs::path resolved(const fs::path& path) {
  std::error_code error;
  fs::path result = fs::weakly_canonical(path, error);
  return error ? fs::absolute(path).lexically_normal() : result;
}

[[noreturn]] void refuse(const OutputFile& output, const std::string& reason) {
  throw UsageError(output.option + ": " + output.path.string() + ": " + reason);
}

// The folder a new file goes to must be a writable directory (or be made one).
void check_folder(const OutputFile& output, const fs::path& folder, MissingFolder missing_folder) {
  const auto cannot_write_into = [&](const std::string& reason) {
    refuse(output, "cannot write into " + folder.string() + " (" + reason + ")");
  };
  std::error_code error;
  if (!fs::exists(folder, error)) {
    if (missing_folder == MissingFolder::refuse) cannot_write_into("no such folder");
    fs::create_directories(folder, error);
    if (error) cannot_write_into("cannot create it: " + error.message());
  }
  if (!fs::is_directory(folder, error)) cannot_write_into("not a folder");
  if (::access(folder.c_str(), W_OK | X_OK) != 0) cannot_write_into("not writable");
}

void check_output(const OutputFile& output, const std::vector<fs::path>& inputs, MissingFolder missing_folder) {
  std::error_code error;
  const fs::file_status status = fs::status(output.path, error);  // a link is followed
  if (!fs::exists(status)) {
    if (fs::is_symlink(fs::symlink_status(output.path, error))) refuse(output, "is a symbolic link to a missing file");
    check_folder(output, folder_of(output.path), missing_folder);
    return;
  }
  if (fs::is_directory(status)) refuse(output, "is a directory");
  for (const fs::path& input : inputs) {
    // Same device and inode: another name, a hard link or a symbolic link is the same file.
    if (fs::equivalent(input, output.path, error)) {
      refuse(output, "is the input " + input.string() + "; writing it would destroy it");
    }
  }
  if (fs::is_character_file(status) || fs::is_fifo(status)) {
    if (::access(output.path.c_str(), W_OK) != 0) refuse(output, "is not writable");
    return;
  }
  if (!fs::is_regular_file(status)) refuse(output, "is neither a regular file, a character device nor a FIFO");
  // A regular file is replaced by a new file in the folder of the file itself (a link is followed).
  const fs::path target = fs::canonical(output.path, error);
  check_folder(output, folder_of(error ? output.path : target), missing_folder);
}

}  // namespace

void check_outputs(const std::vector<OutputFile>& outputs, const std::vector<fs::path>& inputs,
                   MissingFolder missing_folder) {
  for (const OutputFile& output : outputs) check_output(output, inputs, missing_folder);
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (resolved(outputs[i].path) == resolved(outputs[j].path)) {
        refuse(outputs[i], "is also the output of " + outputs[j].option);
      }
    }
  }
}

}  // namespace ontime::cli
