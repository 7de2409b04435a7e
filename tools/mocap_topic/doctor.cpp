#include "mocap_topic/doctor.hpp"

#include <algorithm>
#include <cstdlib>
#include <map>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <mocap/message_type.hpp>
#include <mocap/spelling.hpp>

namespace mocap::doctor {
namespace {

constexpr const char* kLevels[] = {"OK", "WARN", "ERROR", "STALE"};

std::string joined(const std::set<std::string>& names) {
  return fmt::format("{}", fmt::join(names, ", "));
}

class Report {
 public:
  void note(std::string text) { findings_.push_back({false, std::move(text)}); }
  void problem(std::string text) { findings_.push_back({true, std::move(text)}); }
  bool any_problem() const {
    return std::any_of(findings_.begin(), findings_.end(),
                       [](const Finding& f) { return f.problem; });
  }
  std::vector<Finding> take() { return std::move(findings_); }

 private:
  std::vector<Finding> findings_;
};

// Who is up: the processes on the domain by what they publish and announce, with their hosts.
std::set<std::string> report_processes(const Observations& seen, Report& report) {
  std::set<std::string> processes;
  std::map<std::string, std::string> hosts;  // process -> host
  for (const DiscoveredEndpoint& endpoint : seen.endpoints) processes.insert(endpoint.participant);
  for (const AnnouncedParticipant& p : seen.announced) {
    if (p.domain == seen.domain && !p.name.empty()) processes.insert(p.name);
  }
  for (const ProcessDiagnosticsSeen& d : seen.diagnostics) {
    processes.insert(d.process);
    hosts[d.process] = d.host;
  }
  processes.erase(seen.own_participant);
  processes.erase("");
  std::set<std::string> host_names;
  std::vector<std::string> described;
  for (const std::string& process : processes) {
    auto host = hosts.find(process);
    if (host != hosts.end()) host_names.insert(host->second);
    described.push_back(host == hosts.end() ? process
                                            : fmt::format("{} on {}", process, host->second));
  }
  if (processes.empty()) {
    report.problem(fmt::format(
        "nothing runs on DDS domain {}: no participant was heard in {:.0f} s. Do: start the graph "
        "(mocap_launch FILE), on this domain (MOCAP_DOMAIN_ID), where this host can reach it",
        seen.domain, seen.seconds));
  } else {
    report.note(fmt::format("{} process(es) on domain {} ({} host(s) known): {}", processes.size(),
                            seen.domain, host_names.size(), fmt::join(described, ", ")));
  }
  return processes;
}

void report_other_domains(const Observations& seen, Report& report) {
  std::map<int, std::set<std::string>> elsewhere;
  for (const AnnouncedParticipant& p : seen.announced) {
    if (p.domain == seen.domain || p.name == seen.own_participant) continue;
    elsewhere[p.domain].insert(p.name.empty() ? p.guid_prefix : p.name);
  }
  for (const auto& [domain, names] : elsewhere) {
    report.problem(fmt::format(
        "{} participant(s) on DDS domain {}, not {}: {}. Do: use one domain for the graph and "
        "its tools (MOCAP_DOMAIN_ID={} here, or the launch files' dds: domain)",
        names.size(), domain, seen.domain, joined(names), domain));
  }
}

void report_security(const Observations& seen, Report& report) {
  std::set<std::string> seen_participants;
  for (const DiscoveredEndpoint& endpoint : seen.endpoints) {
    seen_participants.insert(endpoint.participant);
  }
  std::set<std::string> hidden;
  for (const AnnouncedParticipant& p : seen.announced) {
    if (p.domain != seen.domain || !p.secure || p.name == seen.own_participant) continue;
    if (!seen_participants.count(p.name)) hidden.insert(p.name.empty() ? p.guid_prefix : p.name);
  }
  if (hidden.empty()) return;
  if (!seen.credentials) {
    report.problem(fmt::format(
        "{} participant(s) on domain {} use DDS Security: {}; without credentials none of "
        "their topics can be seen. Do: run the doctor with --security DIR --identity NAME "
        "(credentials from scripts/make_security.sh), as the graph's tools run",
        hidden.size(), seen.domain, joined(hidden)));
  } else {
    report.problem(fmt::format(
        "{} participant(s) on domain {} use DDS Security and show nothing to these credentials: "
        "{}. Do: check that both sides' credentials come from one certificate authority and that "
        "this identity's permissions allow the topics (scripts/make_security.sh)",
        hidden.size(), seen.domain, joined(hidden)));
  }
}

void report_expectations(const Observations& seen, const Expectations& expected,
                         const std::set<std::string>& processes, Report& report) {
  for (const std::string& group : expected.groups) {
    if (processes.count(group)) continue;
    report.problem(fmt::format(
        "group '{}' of {} is not running: no process of that name on domain {}. Do: start it "
        "(mocap_launch {} --group {}), or look in the launcher's log for why it ended",
        group, expected.file, seen.domain, expected.file, group));
  }
  std::set<std::string> published, subscribed;
  for (const DiscoveredEndpoint& endpoint : seen.endpoints) {
    (endpoint.is_publisher ? published : subscribed).insert(endpoint.topic);
  }
  std::map<std::string, std::vector<const ExpectedEndpoint*>> by_topic;
  for (const ExpectedEndpoint& endpoint : expected.endpoints) {
    by_topic[endpoint.topic].push_back(&endpoint);
  }
  for (const auto& [topic, endpoints] : by_topic) {
    std::set<std::string> readers, writers;
    for (const ExpectedEndpoint* endpoint : endpoints) {
      // Only where the component's own process runs: a group that is down is said above.
      if (!processes.count(endpoint->group)) continue;
      (endpoint->publisher ? writers : readers)
          .insert(fmt::format("{} ({})", endpoint->component, endpoint->group));
    }
    // A component may declare a topic it takes only with some parameters (a camera's pose for
    // a moving camera): what is declared but not read or written now is no problem.
    if (!readers.empty() && !published.count(topic) && subscribed.count(topic)) {
      std::set<std::string> expected_writers;
      for (const ExpectedEndpoint* endpoint : endpoints) {
        if (endpoint->publisher) expected_writers.insert(endpoint->component);
      }
      const std::vector<std::string> candidates(published.begin(), published.end());
      if (const std::string* meant = nearest_spelling(topic, candidates)) {
        report.problem(fmt::format(
            "nobody publishes {}, which {} read(s); {} is published: did you mean {}? Do: "
            "correct the remap",
            topic, joined(readers), *meant, *meant));
      } else if (!expected_writers.empty()) {
        report.problem(
            fmt::format("nobody publishes {}, which {} read(s). Do: check {} (its log, "
                        "its remaps)",
                        topic, joined(readers), joined(expected_writers)));
      } else {
        // An input from outside the file (a re-seed): there may be none.
        report.note(
            fmt::format("{} read(s) {}, which no component of the file publishes and "
                        "nobody publishes now",
                        joined(readers), topic));
      }
    }
    if (!writers.empty() && published.count(topic) && !subscribed.count(topic)) {
      std::set<std::string> expected_readers;
      for (const ExpectedEndpoint* endpoint : endpoints) {
        if (!endpoint->publisher) expected_readers.insert(endpoint->component);
      }
      if (!expected_readers.empty()) {
        report.note(
            fmt::format("nobody reads {} now, which {} publish(es) for {} (down, or not "
                        "reading it with its parameters)",
                        topic, joined(writers), joined(expected_readers)));
      }
    }
  }
}

// Publisher and subscriber pairs DDS will not connect: types, then QoS.
void report_mismatches(const Observations& seen, Report& report) {
  std::map<std::string, std::vector<const DiscoveredEndpoint*>> publishers, subscribers;
  for (const DiscoveredEndpoint& endpoint : seen.endpoints) {
    (endpoint.is_publisher ? publishers : subscribers)[endpoint.topic].push_back(&endpoint);
  }
  for (const auto& [topic, readers] : subscribers) {
    auto writers = publishers.find(topic);
    if (writers == publishers.end()) continue;
    std::set<std::string> said;
    for (const DiscoveredEndpoint* reader : readers) {
      for (const DiscoveredEndpoint* writer : writers->second) {
        std::string line;
        if (writer->type != reader->type) {
          line = fmt::format(
              "{} is published as {} by {} and read as {} by {}: they never connect. Do: give "
              "one of them another topic (a remap), or the same type",
              topic, ros_type_name(writer->type), writer->participant, ros_type_name(reader->type),
              reader->participant);
        } else if (auto why = qos_mismatch(writer->qos, reader->qos)) {
          line = fmt::format(
              "{}: {}'s publisher and {}'s subscriber cannot match ({}): the subscriber gets "
              "nothing. Do: give both the same QoS in their launch files (qos: {{{}: {{profile: "
              "...}}}})",
              topic, writer->participant, reader->participant, *why, topic);
        }
        if (!line.empty() && said.insert(line).second) report.problem(line);
      }
    }
  }
}

void report_clocks(const Observations& seen, const DoctorOptions& options, Report& report) {
  for (const ClockSeen& clock : seen.clocks) {
    const double off_ms = static_cast<double>(clock.offset_ns) * 1e-6;
    const double give_or_take_ms = static_cast<double>(clock.round_trip_ns) * 0.5e-6;
    if (std::abs(off_ms) - give_or_take_ms <= options.clock_warning_ms) continue;
    report.problem(fmt::format(
        "the clock of {} on {} is {:.3f} ms {} this host's (give or take {:.3f} ms): a fusion "
        "refuses cameras over 1 ms off. Do: synchronise the hosts' clocks (README: Clocks; "
        "config/clock/)",
        clock.process, clock.host, std::abs(off_ms), off_ms > 0 ? "ahead of" : "behind",
        give_or_take_ms));
  }
}

void report_diagnostics(const Observations& seen, const std::optional<Expectations>& expected,
                        const std::set<std::string>& processes, const DoctorOptions& options,
                        Report& report) {
  std::set<std::string> reporting;
  for (const ProcessDiagnosticsSeen& process : seen.diagnostics) {
    reporting.insert(process.process);
    if (process.age_s > options.diagnostics_stale_s) {
      report.problem(fmt::format(
          "{} on {} stopped publishing its diagnostics {:.0f} s ago: the process is stuck or "
          "gone. Do: look at its log; mocap_launch restarts a group that dies",
          process.process, process.host, process.age_s));
      continue;
    }
    for (const StatusSeen& status : process.statuses) {
      if (status.level == 0) continue;
      report.problem(fmt::format("{} is {}: {}", status.name,
                                 kLevels[std::clamp(status.level, 0, 3)], status.message));
    }
  }
  if (!expected) return;
  for (const std::string& group : expected->groups) {
    if (processes.count(group) && !reporting.count(group)) {
      report.problem(fmt::format(
          "group '{}' runs but publishes no /diagnostics: it was not started by this build's "
          "mocap_launch, or its callbacks never run. Do: start it with mocap_launch",
          group));
    }
  }
}

}  // namespace

std::vector<Finding> diagnose(const Observations& seen, const std::optional<Expectations>& expected,
                              const DoctorOptions& options) {
  Report report;
  const std::set<std::string> processes = report_processes(seen, report);
  report_other_domains(seen, report);
  report_security(seen, report);
  if (expected) report_expectations(seen, *expected, processes, report);
  report_mismatches(seen, report);
  report_clocks(seen, options, report);
  report_diagnostics(seen, expected, processes, options, report);
  if (!report.any_problem()) {
    std::set<std::string> topics;
    for (const DiscoveredEndpoint& endpoint : seen.endpoints) topics.insert(endpoint.topic);
    size_t statuses = 0;
    for (const ProcessDiagnosticsSeen& process : seen.diagnostics) {
      statuses += process.statuses.size();
    }
    report.note(
        fmt::format("all well: {} process(es), {} topic(s), {} status(es) all OK{}",
                    processes.size(), topics.size(), statuses,
                    expected ? fmt::format(", every group of {} running", expected->file) : ""));
  }
  return report.take();
}

}  // namespace mocap::doctor
