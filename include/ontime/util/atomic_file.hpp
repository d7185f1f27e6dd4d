#pragma once
// Writing output files so that an interruption never leaves a half-written file: the content
// goes to a temporary file in the same directory, is flushed, and is renamed over the target.
// Only regular files (or paths that do not exist yet) are replaced that way: a character
// device or a FIFO (/dev/null, a named pipe) is opened and written directly, so it stays what
// it is. A symbolic link is followed: the file it points to is replaced, the link is kept.

#include <filesystem>
#include <string_view>

namespace ontime {

// Throws UsageError (with the path and the system's reason) when the file cannot be created or
// replaced where asked (a missing or unwritable folder, a directory in the way, a dangling
// link), ResourceLimitError when the disk or quota is full, std::runtime_error for any other
// failure of the system; the target is then left as it was.
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

// The same, for content written piece by piece (a log too large to hold): the pieces go to the
// temporary file (or straight to a device or FIFO) as they come, and commit() puts the file in
// place. Destroyed without commit(), the temporary file is removed and the target is untouched.
// Errors as for write_file_atomically, from the constructor, write() or commit().
class AtomicFileWriter {
 public:
  // Opens the temporary file beside `path` (or `path` itself for a device or FIFO).
  explicit AtomicFileWriter(const std::filesystem::path& path);
  // Without commit(): removes the temporary file, leaving the target as it was.
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  // Appends `piece` to what is written.
  void write(std::string_view piece);
  // Flushes the file to disk and renames it over the target (a device or FIFO: closes it); once, last.
  void commit();

 private:
  std::filesystem::path target_;  // the file replaced (a followed link's target)
  std::string temporary_;         // empty when writing directly to a device or FIFO
  int descriptor_ = -1;
  bool committed_ = false;
  int slot_ = -1;  // in the table of temporary files removed on a signal (remove_temporaries_on_signal)
};

// Throws the error of a file that could not be written for the system's reason `error` (an errno)
// while doing `what` ("cannot create", ...), with the message "PATH: WHAT: REASON": UsageError for
// the caller's to fix (a missing or unwritable folder, a directory in the way, a name too long),
// ResourceLimitError for a full disk or quota, std::runtime_error for any other failure.
[[noreturn]] void throw_file_error(const std::filesystem::path& path, const char* what, int error);

// With `enable`, a termination signal (SIGINT, SIGTERM, SIGHUP, SIGQUIT) removes the temporary
// file of every AtomicFileWriter (and write_file_atomically) alive, then takes its course (the
// handler there before, else the end of the process). The command line enables it; a Python
// interpreter does not (Ctrl-C there is an exception, and the writer's destructor removes the file).
void remove_temporaries_on_signal(bool enable);

}  // namespace ontime
