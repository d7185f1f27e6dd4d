#pragma once
// The end of OnTime's termination-signal handlers (the atomic writers' temporaries, the layered
// solver's scratch): once a handler has cleaned up what is its own, the signal takes its course.

#include <signal.h>
#include <unistd.h>

#include <cstddef>

namespace ontime::detail {

// Restores the handler that was installed before ours for `signal_number` (`previous[i]` for
// `signals[i]`: another cleanup, which ends the process in turn), unblocks the signal and raises
// it; should that return, the default action; should even that return, exit 128 + signal, as a
// shell reports a death by signal. Async-signal-safe: sigaction, pthread_sigmask, raise, signal
// and _exit only.
[[noreturn]] inline void hand_signal_on(int signal_number, const int* signals, const struct sigaction* previous,
                                        std::size_t count) noexcept {
  for (std::size_t i = 0; i < count; ++i) {
    if (signals[i] == signal_number) ::sigaction(signal_number, &previous[i], nullptr);
  }
  sigset_t only;
  sigemptyset(&only);
  sigaddset(&only, signal_number);
  ::pthread_sigmask(SIG_UNBLOCK, &only, nullptr);
  ::raise(signal_number);
  ::signal(signal_number, SIG_DFL);
  ::raise(signal_number);
  ::_exit(128 + signal_number);
}

}  // namespace ontime::detail
