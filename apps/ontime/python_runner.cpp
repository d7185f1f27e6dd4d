#include "python_runner.hpp"

#include <array>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <sys/wait.h>
#include <unistd.h>

namespace ontime::cli {

std::string python_script_directory() {
  if (const char* override_dir = std::getenv("ONTIME_PYTHON_DIR")) return override_dir;
  std::error_code error;
  if (std::filesystem::is_directory(ONTIME_PYTHON_SOURCE_DIR, error)) return ONTIME_PYTHON_SOURCE_DIR;
  return ONTIME_PYTHON_INSTALL_DIR;
}

void run_python_script(const std::string& script, const std::vector<std::string>& arguments) {
  const char* interpreter_override = std::getenv("ONTIME_PYTHON");
  const std::string interpreter = interpreter_override != nullptr ? interpreter_override : "/usr/bin/python3";
  const std::string path = (std::filesystem::path(python_script_directory()) / script).string();
  if (::access(interpreter.c_str(), X_OK) != 0) {
    throw std::runtime_error("plotting needs " + interpreter + " with matplotlib (scripts/setup.sh installs it)");
  }
  std::vector<std::string> command{interpreter, path};
  command.insert(command.end(), arguments.begin(), arguments.end());

  int error_pipe[2];
  if (::pipe(error_pipe) != 0) throw std::runtime_error("cannot start " + interpreter);
  const pid_t child = ::fork();
  if (child < 0) throw std::runtime_error("cannot start " + interpreter);
  if (child == 0) {
    ::dup2(error_pipe[1], STDERR_FILENO);
    ::dup2(error_pipe[1], STDOUT_FILENO);
    ::close(error_pipe[0]);
    std::vector<char*> argv;
    for (std::string& argument : command) argv.push_back(argument.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(error_pipe[1]);
  std::string output;
  std::array<char, 4096> buffer{};
  for (;;) {
    const ssize_t n = ::read(error_pipe[0], buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    output.append(buffer.data(), static_cast<std::size_t>(n));
  }
  ::close(error_pipe[0]);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    while (!output.empty() && output.back() == '\n') output.pop_back();
    throw std::runtime_error("plotting script " + path + " failed" + (output.empty() ? "" : ":\n" + output));
  }
}

}  // namespace ontime::cli
