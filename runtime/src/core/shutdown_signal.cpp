#include "core/shutdown_signal.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <map>
#include <mutex>
#include <thread>

namespace mocap {
namespace {

// Self-pipes: the handler may only call async-signal-safe functions, and write() is one.
int pipe_fds[2] = {-1, -1};    // a stop request (or a wake-up) for wait()
int forced_fds[2] = {-1, -1};  // the forced exit, for its thread
// CLOCK_MONOTONIC nanoseconds of the first signal; 0 before it.
std::atomic<int64_t> first_signal_ns{0};
std::atomic<bool> forcing{false};
static_assert(std::atomic<int64_t>::is_always_lock_free, "read in a signal handler");

std::mutex hooks_mutex;
std::map<uint64_t, std::function<void()>> hooks;
uint64_t next_hook_id = 1;

int64_t monotonic_ns() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);  // async-signal-safe
  return static_cast<int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

void handle(int) {
  int saved_errno = errno;  // the interrupted code may be about to read it
  const int64_t now = std::max<int64_t>(monotonic_ns(), 1);
  int64_t first = 0;
  if (first_signal_ns.compare_exchange_strong(first, now)) {
    char byte = 's';
    [[maybe_unused]] ssize_t ignored = write(pipe_fds[1], &byte, 1);
  } else if (now - first >= std::chrono::nanoseconds(ShutdownSignal::kEscalationDelay).count() &&
             !forcing.exchange(true)) {
    alarm(ShutdownSignal::kForcedExitSeconds);  // should a hook hang
    char byte = 'f';
    [[maybe_unused]] ssize_t ignored = write(forced_fds[1], &byte, 1);
  }
  errno = saved_errno;
}

void open_pipes() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (pipe2(pipe_fds, O_CLOEXEC | O_NONBLOCK) != 0) pipe_fds[0] = pipe_fds[1] = -1;
    if (pipe2(forced_fds, O_CLOEXEC) != 0) forced_fds[0] = forced_fds[1] = -1;
  });
}

// Waits for the forced exit, runs the hooks and ends the process.
void forced_exit_thread() {
  char byte = 0;
  while (read(forced_fds[0], &byte, 1) < 0 && errno == EINTR) {
  }
  constexpr char kMessage[] = "second stop request: forcing the exit\n";
  [[maybe_unused]] ssize_t ignored = write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
  {
    std::lock_guard lock(hooks_mutex);
    for (auto& [id, hook] : hooks) {
      try {
        hook();
      } catch (...) {
      }
    }
  }
  _exit(130);
}

}  // namespace

void ShutdownSignal::install() {
  open_pipes();
  static std::once_flag once;
  std::call_once(once, [] {
    // Started before the handlers: a signal's forced exit always has its thread.
    std::thread(forced_exit_thread).detach();
    struct sigaction action = {};
    action.sa_handler = handle;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
  });
}

bool ShutdownSignal::received() { return first_signal_ns.load() != 0; }

bool ShutdownSignal::wait(std::optional<std::chrono::steady_clock::duration> timeout) {
  open_pipes();
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
  open_pipes();
  char byte = 'w';
  [[maybe_unused]] ssize_t ignored = write(pipe_fds[1], &byte, 1);
}

ForcedExitHook::ForcedExitHook(std::function<void()> hook) {
  std::lock_guard lock(hooks_mutex);
  id_ = next_hook_id++;
  hooks.emplace(id_, std::move(hook));
}

ForcedExitHook::~ForcedExitHook() {
  std::lock_guard lock(hooks_mutex);
  hooks.erase(id_);
}

}  // namespace mocap
