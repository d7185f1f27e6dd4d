#include "support/process.hpp"

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <stdexcept>

namespace ontime::testing {

ProcessResult run_process(const std::vector<std::string>& arguments, int interrupt_after_ms) {
  if (interrupt_after_ms < 0) return run_process(arguments, std::function<bool()>());
  const auto started = std::chrono::steady_clock::now();
  return run_process(arguments, [started, interrupt_after_ms] {
    return std::chrono::steady_clock::now() - started >= std::chrono::milliseconds(interrupt_after_ms);
  });
}

ProcessResult run_process(const std::vector<std::string>& arguments, const std::function<bool()>& interrupt_when,
                          int signal_number) {
  int out_pipe[2], err_pipe[2];
  if (::pipe(out_pipe) != 0 || ::pipe(err_pipe) != 0) throw std::runtime_error("pipe failed");
  const pid_t child = ::fork();
  if (child < 0) throw std::runtime_error("fork failed");
  if (child == 0) {
    ::dup2(out_pipe[1], STDOUT_FILENO);
    ::dup2(err_pipe[1], STDERR_FILENO);
    ::close(out_pipe[0]);
    ::close(err_pipe[0]);
    std::vector<char*> argv;
    for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(out_pipe[1]);
  ::close(err_pipe[1]);
  ProcessResult result;
  bool interrupted = !interrupt_when;
  std::array<pollfd, 2> fds{pollfd{out_pipe[0], POLLIN, 0}, pollfd{err_pipe[0], POLLIN, 0}};
  int open = 2;
  std::array<char, 4096> buffer{};
  while (open > 0) {
    if (!interrupted && interrupt_when()) {
      ::kill(child, signal_number);
      interrupted = true;
    }
    if (::poll(fds.data(), fds.size(), interrupted ? -1 : 5) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (std::size_t i = 0; i < fds.size(); ++i) {
      if (fds[i].fd < 0 || (fds[i].revents & (POLLIN | POLLHUP)) == 0) continue;
      const ssize_t n = ::read(fds[i].fd, buffer.data(), buffer.size());
      if (n <= 0) {
        ::close(fds[i].fd);
        fds[i].fd = -1;
        --open;
      } else {
        (i == 0 ? result.out : result.err).append(buffer.data(), static_cast<std::size_t>(n));
      }
    }
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

}  // namespace ontime::testing
