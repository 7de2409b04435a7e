// Runs launch-file groups as child processes and supervises them: their output, their
// restarts, the deployment's end.
#pragma once

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "launch/restart_policy.hpp"

namespace mocap {

struct ChildProcess {
  std::string name;               // prefix of its output lines: "[name] "
  std::vector<std::string> argv;  // argv[0] is the program path
  // Started again when it dies (a signal, or a non-zero exit) after it has started.
  bool respawn = true;
  // Its death, once started, ends the deployment.
  bool required = false;
};

// Something an operator must hear of: a group restarted, given up on, or gone for good.
struct SupervisorEvent {
  int level = 1;  // 1: handled (restarted), 2: needs a person (given up, required group died)
  std::string text;
};

struct SupervisionOptions {
  // The deployment's length: each start of a group is given what is left of it, appended as
  // "--duration SECONDS". Groups still running 15 s after it are stopped. None: until a stop
  // request.
  std::optional<std::chrono::steady_clock::duration> duration;
  RestartPolicyOptions restarts;
  // Called on the supervising thread for each event.
  std::function<void(const SupervisorEvent&)> on_event;
};

// Starts every child and copies their stdout and stderr line by line with a "[name] " prefix.
// A child says it has started through the pipe named by MOCAP_READY_FD in its environment
// (SupervisorReadyNotice). Then:
// - a child that exits before it has started (bad configuration, a port in use) stops the
//   others: the deployment fails;
// - one that exits with code 0 ends the deployment (the others are stopped);
// - one that dies after it has started (a signal, a non-zero exit) is restarted after a
//   back-off (RestartPolicy), unless it is `required` (the deployment ends) or not `respawn`
//   (it stays down, the others go on); one that dies max_deaths times within the window is
//   given up on, the others go on.
// Stopping (SIGINT or SIGTERM, or after the duration): SIGTERM to each, then a second one after
// 10 s, then SIGKILL. Returns 0, or the exit code of the first child that failed for good
// (128 + the signal for one killed by a signal): one that failed to start, a required one
// that died, one given up on or not restarted.
int supervise(const std::vector<ChildProcess>& children, const SupervisionOptions& options);

// The child's side of MOCAP_READY_FD: made at the start of the process (it takes the variable
// out of the environment, so that programs the child runs do not inherit it), told once the
// group runs.
class SupervisorReadyNotice {
 public:
  SupervisorReadyNotice();
  ~SupervisorReadyNotice();
  SupervisorReadyNotice(const SupervisorReadyNotice&) = delete;
  SupervisorReadyNotice& operator=(const SupervisorReadyNotice&) = delete;
  // Tells the supervisor, if there is one, that the group has started.
  void started();

 private:
  int fd_ = -1;
};

}  // namespace mocap
