// SIGINT/SIGTERM turned into something a thread can wait for.
#pragma once

#include <chrono>
#include <functional>
#include <optional>

#include <mocap/forced_exit_hook.hpp>

namespace mocap {

// The first SIGINT or SIGTERM asks the process to stop gracefully. Signals within
// kEscalationDelay of the first are the same request delivered twice (`timeout` and
// process-group kills signal the process and its group in the same instant; `docker stop`,
// Ctrl-C on a terminal with a supervisor) and are ignored. A signal after that, while the
// graceful stop still runs, forces the exit: the ForcedExitHooks run (at most
// kForcedExitSeconds, then SIGALRM ends the process) and the process exits with status 130.
class ShutdownSignal {
 public:
  static constexpr std::chrono::seconds kEscalationDelay{1};
  static constexpr unsigned kForcedExitSeconds = 5;

  // Installs the handlers (once per process).
  static void install();
  // True once a signal arrived.
  static bool received();
  // Blocks until a signal arrives, `wake()` is called, or `timeout` passes. Returns true for
  // a signal.
  static bool wait(std::optional<std::chrono::steady_clock::duration> timeout);
  // Wakes wait() without a signal (a component asked to stop).
  static void wake();
};

}  // namespace mocap
