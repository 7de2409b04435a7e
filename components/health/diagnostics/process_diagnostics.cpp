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
    for (const TopicCounts& topic : component.published) counts.published[topic.topic] = topic;
    for (const TopicCounts& topic : component.received) counts.received[topic.topic] = topic;
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
  // One topic's figures, in or out; new drops since the last status warn with their cause.
  auto topic_figures = [&](std::string_view direction, const TopicCounts& topic,
                           const std::map<std::string, TopicCounts>& previous,
                           std::string_view drop_cause) {
    auto last = previous.find(topic.topic);
    const TopicCounts& was = last == previous.end() ? TopicCounts{} : last->second;
    runtime.add(fmt::format("{} {} (msg/s)", direction, topic.topic),
                rate(topic.messages, was.messages, seconds));
    if (topic.waiting) {
      runtime.add(fmt::format("{} {} waiting", direction, topic.topic),
                  std::to_string(*topic.waiting));
    }
    if (topic.dropped == 0) return;
    runtime.add(fmt::format("{} {} dropped", direction, topic.topic),
                std::to_string(topic.dropped));
    if (topic.dropped > was.dropped) {
      report.flag(HealthLevel::warn,
                  fmt::format("{} message(s) on {} dropped{}", topic.dropped - was.dropped,
                              topic.topic, drop_cause));
    }
  };
  for (const TopicCounts& topic : component.received) {
    topic_figures("in", topic, before.received,
                  " before it read them: it reads slower than they come (its queue overflowed) "
                  "or they were lost on the way (see its log)");
  }
  for (const TopicCounts& topic : component.published) {
    topic_figures("out", topic, before.published,
                  ": a subscriber had no room (slow, or its host is busy)");
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
