// mocap_topic doctor: why a user sees nothing. What was observed on the DDS domain for a few
// seconds (observations) and what a launch file expects (expectations) become findings, each a
// line that says what is wrong and what to do. The gathering is in doctor_run.cpp; this is the
// reasoning, with no DDS in it, so that each broken set-up can be laid out in a unit test too.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <mocap/qos.hpp>

#include "dds/dds_transport.hpp"
#include "dds/participant_announcements.hpp"

namespace mocap::doctor {

// A topic a component of the launch file publishes or subscribes to, as remapped.
struct ExpectedEndpoint {
  std::string topic;
  std::string type;  // ROS name: pkg/msg/Type
  bool publisher = false;
  std::string component;
  std::string group;
};

struct Expectations {
  std::string file;
  std::vector<std::string> groups;
  std::vector<ExpectedEndpoint> endpoints;  // topic families left out: their topics vary
};

// One status of a process's last /diagnostics.
struct StatusSeen {
  int level = 0;  // diagnostic_msgs' OK 0, WARN 1, ERROR 2, STALE 3
  std::string name;
  std::string message;
};

struct ProcessDiagnosticsSeen {
  std::string process;
  std::string host;
  std::vector<StatusSeen> statuses;
  double age_s = 0;  // since its last array arrived
};

struct ClockSeen {
  std::string process;
  std::string host;
  int64_t offset_ns = 0;  // its clock minus the doctor's
  int64_t round_trip_ns = 0;
};

struct Observations {
  int domain = 0;
  std::vector<int> scanned_domains;
  double seconds = 0;                         // how long it looked
  std::string own_participant;                // the doctor's own name, left out of what it reports
  std::vector<DiscoveredEndpoint> endpoints;  // on `domain`
  std::vector<AnnouncedParticipant> announced;  // on every scanned domain
  std::vector<ProcessDiagnosticsSeen> diagnostics;
  std::vector<ClockSeen> clocks;
  bool credentials = false;  // the doctor joined with DDS Security credentials
};

struct Finding {
  bool problem = false;
  std::string text;  // one line: what is so, and for a problem what to do
};

// Thresholds, as the fusion's defaults (volume_fusion's clock_warning_ms).
struct DoctorOptions {
  double clock_warning_ms = 0.2;
  double diagnostics_stale_s = 3.0;
};

std::vector<Finding> diagnose(const Observations& seen, const std::optional<Expectations>& expected,
                              const DoctorOptions& options = {});

}  // namespace mocap::doctor
