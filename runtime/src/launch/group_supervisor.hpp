// Runs launch-file groups as child processes and supervises them.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace mocap {

struct ChildProcess {
  std::string name;               // prefix of its output lines: "[name] "
  std::vector<std::string> argv;  // argv[0] is the program path
};

// Starts every child, copies their stdout and stderr line by line with a "[name] " prefix,
// and stops them all (SIGTERM, then SIGKILL after 10 s) when one exits, on SIGINT or
// SIGTERM, or after `timeout`. Returns the exit code of the first child that failed, or 0.
// A child killed by a signal counts as failed with 128 + the signal number.
int supervise(const std::vector<ChildProcess>& children,
              std::optional<std::chrono::steady_clock::duration> timeout);

}  // namespace mocap
