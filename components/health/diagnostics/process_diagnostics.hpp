// One process's statuses for /diagnostics, made once a period from what the runtime counts and
// what each component reports (mocap/health.hpp): rates of every topic in and out since the last
// period, drops, callback errors, and the component's own level, message and figures. The
// runtime's counts can raise a component's level (an error in a callback, a message dropped,
// no report for a while); a component's own problems come in its report.
//
//   ProcessDiagnostics diagnostics({.process = "cam_0", .host = "cam-host-0"});
//   for (const DiagnosticStatus& s : diagnostics.update(context.process_health(), now)) ...
//   for (const std::string& change : diagnostics.level_changes()) log(change);
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <mocap/health.hpp>

namespace mocap::health {

struct ProcessDiagnosticsOptions {
  std::string process =
      {};                 // the launch-file group: the statuses are named "<process>/<component>"
  std::string host = {};  // the hardware_id of every status
  // A component whose last report is older than this is STALE: its callbacks do not run.
  std::chrono::nanoseconds stale_after{std::chrono::seconds(3)};
  // The process's own status: how many times mocap_launch started it again and how the last
  // process ended; WARN for `restart_warning` after the start, then OK with the count kept.
  int restarts = 0;
  std::string last_end = {};
  std::chrono::nanoseconds restart_warning{std::chrono::seconds(60)};
};

// A status as diagnostic_msgs/DiagnosticStatus has it.
struct DiagnosticStatus {
  HealthLevel level = HealthLevel::ok;
  std::string name;
  std::string message;
  std::string hardware_id;
  std::vector<std::pair<std::string, std::string>> values;
};

class ProcessDiagnostics {
 public:
  using SteadyTime = std::chrono::steady_clock::time_point;

  // `started`: when the process started, for its restart warning.
  ProcessDiagnostics(ProcessDiagnosticsOptions options, SteadyTime started);

  // The process's status first, then each component's, in the order given. Rates are over the
  // time since the previous call (the first call: since `started`).
  std::vector<DiagnosticStatus> update(const std::vector<ComponentHealth>& components,
                                       SteadyTime now);
  // What changed level in the last update(), one line each ("cam_0/fiducials: OK -> WARN: ..."),
  // for the log: a level change is said once, not every period.
  const std::vector<std::string>& level_changes() const { return changes_; }

 private:
  struct Counts {
    std::map<std::string, TopicCounts> published, received;  // by topic
    uint64_t callback_errors = 0;
  };

  DiagnosticStatus process_status(SteadyTime now) const;
  DiagnosticStatus component_status(const ComponentHealth& component, const Counts& before,
                                    double seconds, SteadyTime now) const;
  void note_level(const DiagnosticStatus& status);

  ProcessDiagnosticsOptions options_;
  SteadyTime started_;
  SteadyTime last_update_;
  std::map<std::string, Counts> counts_;       // by component, at the last update
  std::map<std::string, HealthLevel> levels_;  // by status name, at the last update
  std::vector<std::string> changes_;
};

}  // namespace mocap::health
