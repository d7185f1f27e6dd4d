#pragma once
// What the CLI tests share (tests/apps/cli_*_test.cpp, built into one executable, cli_test): the
// ontime tool run as a child process, the paper's instances, a fresh scratch folder per test and
// files read whole.

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "support/paper.hpp"
#include "support/process.hpp"

namespace ontime::cli_test {

using nlohmann::json;

// Runs the ontime tool built with the tests (no shell) and captures its exit code and output.
inline testing::ProcessResult ontime(std::vector<std::string> arguments) {
  arguments.insert(arguments.begin(), ONTIME_CLI);
  return testing::run_process(arguments);
}

// The path of one of the paper's instances (data/instances/paper/NAME.json).
inline std::string paper(const std::string& name) {
  return testing::source_path("data/instances/paper/" + name + ".json").string();
}

// A folder of the system's temporary directory for one test, emptied: the tests run in parallel.
inline std::filesystem::path scratch(const std::string& name) {
  const auto directory = std::filesystem::temp_directory_path() / ("ontime_cli_test_" + name);
  std::filesystem::remove_all(directory);
  std::filesystem::create_directories(directory);
  return directory;
}

inline std::size_t line_count(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::size_t lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  return lines;
}

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace ontime::cli_test
