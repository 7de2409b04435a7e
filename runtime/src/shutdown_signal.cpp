#include "shutdown_signal.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <mutex>

namespace mocap {
namespace {

// A self-pipe: the handler may only call async-signal-safe functions, and write() is one.
int pipe_fds[2] = {-1, -1};
std::atomic<int> signals_received{0};

void handle(int) {
  if (signals_received.fetch_add(1) >= 1) _exit(130);
  int saved_errno = errno;  // the interrupted code may be about to read it
  char byte = 's';
  [[maybe_unused]] ssize_t ignored = write(pipe_fds[1], &byte, 1);
  errno = saved_errno;
}

void open_pipe() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (pipe2(pipe_fds, O_CLOEXEC | O_NONBLOCK) != 0) pipe_fds[0] = pipe_fds[1] = -1;
  });
}

}  // namespace

void ShutdownSignal::install() {
  open_pipe();
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction action = {};
    action.sa_handler = handle;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
  });
}

bool ShutdownSignal::received() { return signals_received.load() > 0; }

bool ShutdownSignal::wait(std::optional<std::chrono::steady_clock::duration> timeout) {
  open_pipe();
  auto deadline = timeout ? std::chrono::steady_clock::now() + *timeout
                          : std::chrono::steady_clock::time_point::max();
  for (;;) {
    if (received()) return true;
    int wait_ms = -1;
    if (timeout) {
      auto left = deadline - std::chrono::steady_clock::now();
      if (left <= std::chrono::steady_clock::duration::zero()) return false;
      wait_ms = static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(left).count());
    }
    pollfd fd = {pipe_fds[0], POLLIN, 0};
    int ready = poll(&fd, 1, wait_ms);
    if (ready > 0) {
      char bytes[16];
      bool woken = false;
      ssize_t n;
      while ((n = read(pipe_fds[0], bytes, sizeof bytes)) > 0) {
        for (ssize_t i = 0; i < n; ++i) woken |= bytes[i] == 'w';
      }
      if (received()) return true;
      if (woken) return false;
    } else if (ready < 0 && errno != EINTR) {
      return received();
    }
  }
}

void ShutdownSignal::wake() {
  open_pipe();
  char byte = 'w';
  [[maybe_unused]] ssize_t ignored = write(pipe_fds[1], &byte, 1);
}

}  // namespace mocap
