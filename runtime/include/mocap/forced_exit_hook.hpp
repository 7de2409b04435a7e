// What must be done even when a process's exit is forced.
#pragma once

#include <cstdint>
#include <functional>

namespace mocap {

// Runs `hook` at a forced exit while this object lives. The exit is forced by a second stop
// request (SIGINT or SIGTERM) that comes well after the first (ShutdownSignal's escalation
// delay, 1 s) while the graceful stop still runs: a callback that never returns, a device that
// never answers. Every hook alive then runs, for at most 5 s in all, and the process exits with
// status 130 without destroying anything: no destructor, no component's stop.
//
// The hook runs on a thread of its own while the other threads may be anywhere, so it takes
// only what is safe to take from any thread. What it is for: a bag's metadata written from what
// the database holds, a motor told to stop.
class ForcedExitHook {
 public:
  explicit ForcedExitHook(std::function<void()> hook);
  ~ForcedExitHook();
  ForcedExitHook(const ForcedExitHook&) = delete;
  ForcedExitHook& operator=(const ForcedExitHook&) = delete;

 private:
  uint64_t id_;
};

}  // namespace mocap
