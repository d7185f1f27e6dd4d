#include "python_runner.hpp"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "install_paths.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"

namespace ontime::cli {
namespace {

// The signals forwarded to the script's process group while it runs.
constexpr std::array<int, 3> kForwardedSignals{SIGINT, SIGTERM, SIGHUP};

// Shared with the signal handler, hence lock-free atomics: the script's process group (0 before
// it exists) and the first forwarded signal received (0 for none).
std::atomic<pid_t> script_process_group{0};
std::atomic<int> received_signal{0};
static_assert(std::atomic<pid_t>::is_always_lock_free);
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void forward_signal(int signal_number) {
  int none = 0;
  received_signal.compare_exchange_strong(none, signal_number);
  const pid_t group = script_process_group.load();
  if (group > 0) ::kill(-group, signal_number);
}

// Installs forward_signal for kForwardedSignals (except those ignored, as under nohup) for its
// lifetime, and puts the previous dispositions back afterwards.
class SignalForwarding {
 public:
  SignalForwarding() {
    received_signal.store(0);
    struct sigaction forwarding {};
    forwarding.sa_handler = forward_signal;
    sigemptyset(&forwarding.sa_mask);
    for (std::size_t i = 0; i < kForwardedSignals.size(); ++i) {
      ::sigaction(kForwardedSignals[i], nullptr, &previous_[i]);
      if (previous_[i].sa_handler != SIG_IGN) ::sigaction(kForwardedSignals[i], &forwarding, nullptr);
    }
  }
  ~SignalForwarding() {
    script_process_group.store(0);
    for (std::size_t i = 0; i < kForwardedSignals.size(); ++i)
      ::sigaction(kForwardedSignals[i], &previous_[i], nullptr);
  }
  SignalForwarding(const SignalForwarding&) = delete;
  SignalForwarding& operator=(const SignalForwarding&) = delete;

 private:
  std::array<struct sigaction, kForwardedSignals.size()> previous_{};
};

// A directory of the system's temporary folder, removed with its content when it goes out of scope.
class TemporaryDirectory {
 public:
  TemporaryDirectory() {
    std::error_code error;
    const std::filesystem::path base = std::filesystem::temp_directory_path(error);
    if (error) throw UsageError("cannot draw: no temporary folder ($TMPDIR): " + error.message());
    std::string pattern = (base / "ontime-plot-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw UsageError("cannot draw: cannot create a folder in the temporary folder " + base.string() +
                       " ($TMPDIR): " + std::strerror(errno));
    }
    path_ = pattern;
  }
  ~TemporaryDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// The last non-empty line of `text`, shortened for a one-line message.
std::string last_line(std::string_view text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.remove_suffix(1);
  const std::size_t newline = text.find_last_of('\n');
  return shortened_label(newline == std::string_view::npos ? text : text.substr(newline + 1), 1000);
}

// Dies of `signal_number`. The disposition in force before the script ran handles it first (a
// caller's handler, e.g. train's OutputSet removing its staged files before it ends the
// process); if that returns, the default action ends the process (exit status 128 + number).
[[noreturn]] void die_of(int signal_number) {
  sigset_t only;
  sigemptyset(&only);
  sigaddset(&only, signal_number);
  ::pthread_sigmask(SIG_UNBLOCK, &only, nullptr);
  std::raise(signal_number);
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
  std::_Exit(128 + signal_number);
}

}  // namespace

std::string python_script_directory() {
  if (const char* override_dir = std::getenv("ONTIME_PYTHON_DIR")) return override_dir;
  const std::filesystem::path installed = beside_executable(ONTIME_PYTHON_FROM_BINDIR);
  std::error_code error;
  if (std::filesystem::is_directory(installed, error)) return installed.string();
  if (std::filesystem::is_directory(ONTIME_PYTHON_SOURCE_DIR, error)) return ONTIME_PYTHON_SOURCE_DIR;
  return installed.string();
}

std::string shortened_label(std::string_view text, std::size_t max_characters) {
  const auto starts_character = [](char byte) { return (static_cast<unsigned char>(byte) & 0xC0) != 0x80; };
  const auto characters = static_cast<std::size_t>(std::count_if(text.begin(), text.end(), starts_character));
  if (characters <= max_characters) return std::string(text);
  // Keep max_characters - 1 characters and the ellipsis.
  std::size_t kept = 0;
  std::size_t end = 0;
  while (end < text.size() && (!starts_character(text[end]) || kept++ < max_characters - 1)) ++end;
  return std::string(text.substr(0, end)) + "…";
}

void run_python_script(const std::string& script, const std::filesystem::path& output,
                       const std::function<std::vector<std::string>(const std::string& drawing)>& arguments) {
  const char* interpreter_override = std::getenv("ONTIME_PYTHON");
  const std::string interpreter = interpreter_override != nullptr ? interpreter_override : "/usr/bin/python3";
  const std::string path = (std::filesystem::path(python_script_directory()) / script).string();
  if (::access(interpreter.c_str(), X_OK) != 0) {
    throw UsageError("plotting needs " + interpreter +
                     " with matplotlib (scripts/setup.sh installs it; $ONTIME_PYTHON names another interpreter)");
  }
  if (::access(path.c_str(), R_OK) != 0) throw std::runtime_error("cannot read the plotting script " + path);

  const TemporaryDirectory directory;
  // The figure keeps the output's name, whose extension tells matplotlib the format.
  const std::filesystem::path drawing =
      directory.path() / (output.has_filename() ? output.filename() : std::filesystem::path("figure.png"));
  std::vector<std::string> command{interpreter, path};
  const std::vector<std::string> script_arguments = arguments(drawing.string());
  command.insert(command.end(), script_arguments.begin(), script_arguments.end());
  // Everything the child needs is prepared before fork: only async-signal-safe calls follow.
  std::vector<char*> argv;
  argv.reserve(command.size() + 1);
  for (std::string& argument : command) argv.push_back(argument.data());
  argv.push_back(nullptr);
  const std::string exec_failure = "cannot run " + interpreter + "\n";

  int error_pipe[2];
  if (::pipe2(error_pipe, O_CLOEXEC) != 0) throw std::runtime_error("cannot start " + interpreter);
  const pid_t parent = ::getpid();
  std::string output_text;
  int status = 0;
  {
    const SignalForwarding forwarding;
    const pid_t child = ::fork();
    if (child < 0) {
      ::close(error_pipe[0]);
      ::close(error_pipe[1]);
      throw std::runtime_error("cannot start " + interpreter);
    }
    if (child == 0) {
      // Its own process group, so that a terminal's Ctrl-C reaches ontime only and arrives once,
      // forwarded; killed if ontime dies without forwarding (SIGKILL).
      ::setpgid(0, 0);
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent) ::_exit(127);
      for (const int signal_number : kForwardedSignals) {
        struct sigaction current {};
        ::sigaction(signal_number, nullptr, &current);
        if (current.sa_handler != SIG_IGN) ::signal(signal_number, SIG_DFL);
      }
      const int nothing = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
      if (nothing >= 0) ::dup2(nothing, STDIN_FILENO);
      ::dup2(error_pipe[1], STDERR_FILENO);
      ::dup2(error_pipe[1], STDOUT_FILENO);
      ::execv(argv[0], argv.data());
      [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, exec_failure.data(), exec_failure.size());
      ::_exit(127);
    }
    ::setpgid(child, child);  // also here: a signal may come before the child has run
    script_process_group.store(child);
    if (const int early = received_signal.load(); early != 0) ::kill(-child, early);
    ::close(error_pipe[1]);
    // Only the end of the output is kept: its last line is the script's message.
    constexpr std::size_t kKeptBytes = std::size_t{64} * 1024;
    std::array<char, 4096> buffer{};
    for (;;) {
      const ssize_t n = ::read(error_pipe[0], buffer.data(), buffer.size());
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      output_text.append(buffer.data(), static_cast<std::size_t>(n));
      if (output_text.size() > 2 * kKeptBytes) output_text.erase(0, output_text.size() - kKeptBytes);
    }
    ::close(error_pipe[0]);
    while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
    }
  }
  if (const int signal_number = received_signal.load(); signal_number != 0) {
    std::error_code ignored;
    std::filesystem::remove_all(directory.path(), ignored);
    die_of(signal_number);
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    std::ifstream figure(drawing, std::ios::binary);
    if (!figure) throw std::runtime_error(path + " wrote no figure");
    write_file_atomically(output, std::string(std::istreambuf_iterator<char>(figure), {}));
    return;
  }
  const std::string message = last_line(output_text);
  if (WIFEXITED(status) && WEXITSTATUS(status) == kScriptBadInputExit) {
    throw InputError(output.string(), "drawing", message);
  }
  const std::string reason = WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                                 : "exit status " + std::to_string(WEXITSTATUS(status));
  throw std::runtime_error("drawing " + output.string() + " failed (" + reason + ")" +
                           (message.empty() ? "" : ": " + message));
}

}  // namespace ontime::cli
