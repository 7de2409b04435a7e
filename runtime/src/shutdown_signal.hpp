// SIGINT/SIGTERM turned into something a thread can wait for.
#pragma once

#include <chrono>
#include <optional>

namespace mocap {

// The first SIGINT or SIGTERM asks the process to stop gracefully; a second one exits at
// once with status 130, in case a component hangs on its way out.
class ShutdownSignal {
 public:
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
