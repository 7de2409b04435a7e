#include "health/diagnostics/process_diagnostics.hpp"

#include <fmt/format.h>

namespace mocap::health {
namespace {

std::string rate(uint64_t now, uint64_t before, double seconds) {
  return seconds > 0 ? fmt::format("{:.1f}", static_cast<double>(now - before) / seconds) : "-";
}

}  // namespace

ProcessDiagnostics::ProcessDiagnostics(ProcessDiagnosticsOptions options, SteadyTime started)
    : options_(std::move(options)), started_(started), last_update_(started) {}

std::vector<DiagnosticStatus> ProcessDiagnostics::update(
    const std::vector<ComponentHealth>& components, SteadyTime now) {
  const double seconds = std::chrono::duration<double>(now - last_update_).count();
  changes_.clear();
  std::vector<DiagnosticStatus> statuses;
  statuses.push_back(process_status(now));
  note_level(statuses.back());
  for (const ComponentHealth& component : components) {
    Counts& counts = counts_[component.name];
    statuses.push_back(component_status(component, counts, seconds, now));
    note_level(statuses.back());
    counts = {};
    for (const TopicCounts& topic : component.published) {
      counts.published[topic.topic] = topic.messages;
      counts.dropped[topic.topic] = topic.dropped;
    }
    for (const TopicCounts& topic : component.received) {
      counts.received[topic.topic] = topic.messages;
      counts.dropped_in[topic.topic] = topic.dropped;
    }
    counts.callback_errors = component.callback_errors;
  }
  last_update_ = now;
  return statuses;
}

DiagnosticStatus ProcessDiagnostics::process_status(SteadyTime now) const {
  DiagnosticStatus status{HealthLevel::ok, options_.process, "OK", options_.host, {}};
  status.values.emplace_back("host", options_.host);
  status.values.emplace_back(
      "running for (s)",
      fmt::format("{:.0f}", std::chrono::duration<double>(now - started_).count()));
  status.values.emplace_back("restarts", std::to_string(options_.restarts));
  if (options_.restarts > 0) {
    status.values.emplace_back("last process", options_.last_end);
    if (now - started_ < options_.restart_warning) {
      status.level = HealthLevel::warn;
      status.message =
          fmt::format("started again by mocap_launch ({} time(s)); the last process {}",
                      options_.restarts, options_.last_end);
    }
  }
  return status;
}

DiagnosticStatus ProcessDiagnostics::component_status(const ComponentHealth& component,
                                                      const Counts& before, double seconds,
                                                      SteadyTime now) const {
  HealthReport report = component.report;
  HealthReport runtime;
  for (const TopicCounts& topic : component.received) {
    auto it = before.received.find(topic.topic);
    runtime.add(fmt::format("in {} (msg/s)", topic.topic),
                rate(topic.messages, it == before.received.end() ? 0 : it->second, seconds));
    if (topic.waiting) {
      runtime.add(fmt::format("in {} waiting", topic.topic), std::to_string(*topic.waiting));
    }
    if (topic.dropped == 0) continue;
    runtime.add(fmt::format("in {} dropped", topic.topic), std::to_string(topic.dropped));
    auto dropped_before = before.dropped_in.find(topic.topic);
    const uint64_t new_drops =
        topic.dropped - (dropped_before == before.dropped_in.end() ? 0 : dropped_before->second);
    if (new_drops > 0) {
      report.flag(HealthLevel::warn,
                  fmt::format("{} message(s) on {} dropped before it read them: it reads slower "
                              "than they come (its queue overflowed) or they were lost on the "
                              "way (see its log)",
                              new_drops, topic.topic));
    }
  }
  for (const TopicCounts& topic : component.published) {
    auto it = before.published.find(topic.topic);
    runtime.add(fmt::format("out {} (msg/s)", topic.topic),
                rate(topic.messages, it == before.published.end() ? 0 : it->second, seconds));
    if (topic.dropped == 0) continue;
    runtime.add(fmt::format("out {} dropped", topic.topic), std::to_string(topic.dropped));
    auto dropped_before = before.dropped.find(topic.topic);
    const uint64_t new_drops =
        topic.dropped - (dropped_before == before.dropped.end() ? 0 : dropped_before->second);
    if (new_drops > 0) {
      report.flag(HealthLevel::warn,
                  fmt::format("{} message(s) on {} dropped: a subscriber had no room (slow, or "
                              "its host is busy)",
                              new_drops, topic.topic));
    }
  }
  runtime.add("callback errors", std::to_string(component.callback_errors));
  if (component.callback_errors > before.callback_errors) {
    report.flag(HealthLevel::error,
                fmt::format("{} callback(s) threw since the last status: see its log",
                            component.callback_errors - before.callback_errors));
  }
  // Never reported: as old as the process (its first report is due a second after the start).
  const SteadyTime reported =
      component.reported_at == SteadyTime{} ? started_ : component.reported_at;
  if (now - reported > options_.stale_after) {
    report.flag(HealthLevel::stale,
                fmt::format("no report for {:.0f} s: its callbacks do not run (one is stuck?)",
                            std::chrono::duration<double>(now - reported).count()));
  }
  DiagnosticStatus status{report.level,
                          options_.process + "/" + component.name,
                          report.message.empty() ? "OK" : report.message,
                          options_.host,
                          {}};
  status.values.emplace_back("plugin", component.plugin);
  status.values.insert(status.values.end(), report.values.begin(), report.values.end());
  status.values.insert(status.values.end(), runtime.values.begin(), runtime.values.end());
  return status;
}

void ProcessDiagnostics::note_level(const DiagnosticStatus& status) {
  auto [it, first] = levels_.try_emplace(status.name, HealthLevel::ok);
  if (it->second == status.level && !(first && status.level != HealthLevel::ok)) return;
  changes_.push_back(fmt::format("{}: {} -> {}: {}", status.name, to_string(it->second),
                                 to_string(status.level),
                                 status.message.empty() ? "OK" : status.message));
  it->second = status.level;
}

}  // namespace mocap::health
