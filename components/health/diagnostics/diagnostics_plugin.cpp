// diagnostics: this process's statuses on /diagnostics, once a period, as ROS 2 publishes them
// (diagnostic_msgs/DiagnosticArray: rqt_runtime_monitor, ROS 2's aggregator and Foxglove's
// Diagnostics panels read it); and its clock, to whoever probes it (/mocap/clock/probe), with
// the topics its components publish, so that a fusion knows whose clock stamps what it fuses.
// mocap_launch adds one to every group of a launch file.
#include <unistd.h>

#include <chrono>
#include <mutex>
#include <random>
#include <set>
#include <string>

#include <diagnostic_msgs/msg/diagnostic_array.hpp>
#include <mocap/component.hpp>
#include <mocap/launch_start.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/clock_probe.hpp>
#include <mocap_msgs/msg/clock_probe_reply.hpp>

#include "common/topics/graph_topics.hpp"
#include "health/diagnostics/process_diagnostics.hpp"

namespace mocap::health {
namespace {

using diagnostic_msgs::msg::DiagnosticArray;
using mocap_msgs::msg::ClockProbe;
using mocap_msgs::msg::ClockProbeReply;

struct Settings {
  double period_s = 1.0;
  double stale_after_s = 3.0;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("period_s", "seconds between two publications of the statuses", &Settings::period_s)
        .range(0.05, 60)
        .add("stale_after_s",
             "a component whose last report is older than this is STALE: its callbacks do not run",
             &Settings::stale_after_s)
        .range(0.1, 3600);

std::string host_name() {
  char name[256] = {};
  if (gethostname(name, sizeof name - 1) != 0) return "unknown";
  return name;
}

std::chrono::nanoseconds seconds(double s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(s));
}

class Diagnostics final : public Component {
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Publishes this process's statuses on /diagnostics once a period (diagnostic_msgs, as "
        "ROS 2 does): each component's level, message and figures, with the topics' rates, "
        "drops and callback errors the runtime counts, and the process's restarts; answers clock "
        "probes so that a fusion can measure this host's clock. mocap_launch adds one to every "
        "group.");
    kParameters.declare(spec);
    spec.publishes<DiagnosticArray>(topics::kDiagnostics, kDiagnosticsQos,
                                    "this process's statuses: the process, then each component");
    spec.subscribes<ClockProbe>(topics::kClockProbe, Qos::sensor_data(),
                                "clock probes from any process");
    spec.publishes<ClockProbeReply>(topics::kClockReply, Qos::sensor_data(),
                                    "the answers: the probe's times and this process's, with the "
                                    "topics its components publish");
  }

  explicit Diagnostics(Context& context)
      : Component(context),
        host_(host_name()),
        instance_(std::random_device{}() * 4294967296ull + std::random_device{}()),
        diagnostics_({.process = context.process_name(),
                      .host = host_,
                      .stale_after = seconds(settings_.stale_after_s),
                      .restarts = group_restarts(),
                      .last_end = last_end()},
                     std::chrono::steady_clock::now()) {
    statuses_ = create_publisher<DiagnosticArray>(topics::kDiagnostics);
    replies_ = create_publisher<ClockProbeReply>(topics::kClockReply);
    note_topics(context.process_health());
    create_subscription<ClockProbe>(topics::kClockProbe,
                                    [this](const ClockProbe& probe) { answer(probe); });
    // The statuses on a thread of their own: gathering and sending them takes a fraction of a
    // millisecond, which on the component's strand would delay the answers to clock probes
    // (their arrival times are what the asker measures) and keep them off the DDS thread that
    // runs quick callbacks at once.
    create_worker("statuses", [this, period = seconds(settings_.period_s)](std::stop_token stop) {
      while (wait_for_stop(stop, period)) publish();
    });
  }

 private:
  static constexpr Qos kDiagnosticsQos{Reliability::Reliable, Durability::Volatile,
                                       History::KeepLast, 10};

  static std::string last_end() {
    const char* text = std::getenv(kGroupLastEndVariable);
    return text ? text : "";
  }

  // The topics this process's components publish: those of their constructors (this component
  // is the last made), then as each status finds them. An answer only copies them: the less it
  // does, the sooner it runs after the probe arrived, and the truer the clock it tells.
  void note_topics(const std::vector<ComponentHealth>& components) {
    std::set<std::string> topics;
    for (const ComponentHealth& component : components) {
      for (const TopicCounts& topic : component.published) topics.insert(topic.topic);
    }
    std::lock_guard lock(topics_mutex_);
    published_topics_.assign(topics.begin(), topics.end());
  }

  void answer(const ClockProbe& probe) {
    const auto received = now();
    ClockProbeReply reply;
    reply.requester(probe.requester());
    reply.number(probe.number());
    reply.probe_sent(probe.sent());
    reply.received(to_time_msg(received));
    reply.instance(instance_);
    reply.host(host_);
    reply.process(context().process_name());
    {
      std::lock_guard lock(topics_mutex_);
      reply.topics(published_topics_);
    }
    reply.sent(to_time_msg(now()));
    replies_.publish(std::move(reply));
  }

  void publish() {
    const std::vector<ComponentHealth> components = context().process_health();
    note_topics(components);
    DiagnosticArray array;
    array.header().stamp(to_time_msg(now()));
    for (const DiagnosticStatus& status :
         diagnostics_.update(components, std::chrono::steady_clock::now())) {
      diagnostic_msgs::msg::DiagnosticStatus& out = array.status().emplace_back();
      out.level(static_cast<uint8_t>(status.level));
      out.name(status.name);
      out.message(status.message);
      out.hardware_id(status.hardware_id);
      for (const auto& [key, value] : status.values) {
        diagnostic_msgs::msg::KeyValue& pair = out.values().emplace_back();
        pair.key(key);
        pair.value(value);
      }
    }
    for (const std::string& change : diagnostics_.level_changes()) {
      if (change.find("-> OK") != std::string::npos) {
        log().info("{}", change);
      } else {
        log().warn("{}", change);
      }
    }
    statuses_.publish(std::move(array));
  }

  const std::string host_;
  const uint64_t instance_;
  ProcessDiagnostics diagnostics_;  // the statuses worker's alone
  std::mutex topics_mutex_;         // the worker writes the topics, the answers read them
  std::vector<std::string> published_topics_;
  Publisher<DiagnosticArray> statuses_;
  Publisher<ClockProbeReply> replies_;
};

}  // namespace
}  // namespace mocap::health

MOCAP_REGISTER_COMPONENT(mocap::health::Diagnostics, "diagnostics")
