#pragma once
// Writing output files so that an interruption never leaves a half-written file: the content
// goes to a temporary file in the same directory, is flushed, and is renamed over the target.

#include <filesystem>
#include <string_view>

namespace ontime {

// Throws std::runtime_error (with the path and the system's reason) when writing fails; the
// target is then left as it was.
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

}  // namespace ontime
