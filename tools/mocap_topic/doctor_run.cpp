#include "mocap_topic/doctor_run.hpp"

#include <condition_variable>
#include <future>
#include <map>
#include <mutex>
#include <set>

#include <fmt/format.h>

#include <diagnostic_msgs/msg/diagnostic_array.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/clock_probe.hpp>
#include <mocap_msgs/msg/clock_probe_reply.hpp>

#include "core/names.hpp"
#include "core/shutdown_signal.hpp"
#include "health/clock_offset/clock_offset.hpp"
#include "host/dds_implementations.hpp"
#include "host/plugin_loader.hpp"
#include "launch/launch_file.hpp"
#include "mocap_topic/doctor.hpp"

namespace mocap::doctor {
namespace {

using diagnostic_msgs::msg::DiagnosticArray;
using mocap_msgs::msg::ClockProbe;
using mocap_msgs::msg::ClockProbeReply;

constexpr const char* kParticipant = "mocap_doctor";
// A host's clock is as well known as the quickest exchange with it (half its round trip), and
// the filter keeps the last two seconds' exchanges: a hundred a second leave, on a busy
// machine, one quick enough to tell 5 ms ahead within 0.1 ms (ten a second measured 5.102 ms,
// round trip 0.34 ms, beside CI's other tests).
constexpr auto kProbePeriod = std::chrono::milliseconds(10);

Expectations expectations_of(const LaunchFile& file) {
  Expectations expected{file.path, {}, {}};
  for (const LaunchGroup& group : file.groups) {
    expected.groups.push_back(group.name);
    for (const LaunchComponent& component : group.components) {
      for (const TopicSpec& declared : component.plugin->spec.topics()) {
        if (declared.type == nullptr) continue;
        auto remap = component.config.remaps.find(declared.topic);
        const std::string topic =
            remap == component.config.remaps.end() ? declared.topic : remap->second;
        if (is_topic_family(topic)) continue;
        expected.endpoints.push_back({topic, declared.type->name(),
                                      declared.direction == TopicDirection::Publish,
                                      component.config.name, group.name});
      }
    }
  }
  return expected;
}

// Wakes the doctor's loop when a message arrives: a clock reply is stamped as it arrives.
class Doorbell {
 public:
  void ring() {
    std::lock_guard lock(mutex_);
    rung_ = true;
    woken_.notify_one();
  }
  void wait_until(std::chrono::steady_clock::time_point deadline) {
    std::unique_lock lock(mutex_);
    woken_.wait_until(lock, deadline, [this] { return rung_; });
    rung_ = false;
  }

 private:
  std::mutex mutex_;
  std::condition_variable woken_;
  bool rung_ = false;
};

// Messages of one topic as they arrive, taken on this thread.
class Inbox {
 public:
  Inbox(DdsTransport& transport, const std::string& topic, const MessageType& type, const Qos& qos,
        Doorbell& doorbell)
      : subscription_(transport.subscribe({topic, &type, qos, kParticipant},
                                          [&doorbell](bool) { doorbell.ring(); })) {}
  template <class Message, class Each>
  void take_all(Each each) {
    ReceivedMessage received;
    while (subscription_->take(received)) {
      each(*std::static_pointer_cast<const Message>(received.message));
    }
  }

 private:
  std::unique_ptr<TransportSubscription> subscription_;
};

}  // namespace

int run_doctor(const DoctorCommand& command) {
  std::optional<Expectations> expected;
  DdsOptions dds;
  if (command.launch_file) {
    PluginLoader plugins;
    try {
      const LaunchFile file = load_launch_file(*command.launch_file, plugins);
      expected = expectations_of(file);
      dds = file.dds;
    } catch (const LaunchError& e) {
      for (const std::string& problem : e.problems()) fmt::print(stderr, "{}\n", problem);
      fmt::print(stderr,
                 "mocap_topic doctor: {} does not load; fix it first (mocap_launch {} "
                 "--check)\n",
                 *command.launch_file, *command.launch_file);
      return 2;
    }
  }
  dds.security_directory = command.security_directory;
  dds.security_identity = command.security_identity;
  Observations seen;
  seen.own_participant = kParticipant;
  seen.seconds = command.seconds;
  seen.credentials = !command.security_directory.empty();
  try {
    auto transport = make_dds_transport(dds, kParticipant);
    seen.domain = transport->domain_id();
    std::set<int> domains(command.domains.begin(), command.domains.end());
    if (domains.empty()) {
      for (int d = 0; d <= 9; ++d) domains.insert(d);
    }
    domains.insert(seen.domain);
    seen.scanned_domains.assign(domains.begin(), domains.end());
    const auto duration = std::chrono::milliseconds(static_cast<int>(command.seconds * 1000));
    auto announcements = std::async(std::launch::async, [&] {
      return listen_for_participants(seen.scanned_domains, duration);
    });

    Doorbell doorbell;
    Inbox diagnostics(*transport, "/diagnostics", message_type<DiagnosticArray>(),
                      {Reliability::Reliable, Durability::Volatile, History::KeepLast, 10},
                      doorbell);
    Inbox replies(*transport, "/mocap/clock/reply", message_type<ClockProbeReply>(),
                  {Reliability::BestEffort, Durability::Volatile, History::KeepLast, 100},
                  doorbell);
    auto probes = transport->advertise(
        {"/mocap/clock/probe", &message_type<ClockProbe>(), Qos::sensor_data(), kParticipant});
    std::map<std::string, std::pair<DiagnosticArray, std::chrono::steady_clock::time_point>> last;
    health::PeerClocks clocks;
    const auto end = std::chrono::steady_clock::now() + duration;
    uint32_t number = 0;
    auto next_probe = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() < end && !ShutdownSignal::received()) {
      if (std::chrono::steady_clock::now() >= next_probe) {
        auto probe = std::make_shared<ClockProbe>();
        probe->requester(kParticipant);
        probe->number(++number);
        probe->sent(to_time_msg(Clock::now()));
        probes->publish(probe, Clock::now());
        next_probe += kProbePeriod;
      }
      doorbell.wait_until(std::min(next_probe, end));
      diagnostics.take_all<DiagnosticArray>([&](const DiagnosticArray& array) {
        if (array.status().empty()) return;
        last[array.status().front().name()] = {array, std::chrono::steady_clock::now()};
      });
      replies.take_all<ClockProbeReply>([&](const ClockProbeReply& reply) {
        if (reply.requester() != kParticipant) return;
        // Known by its process's name, which its diagnostics carry (not by its topics).
        clocks.add(reply.instance(), reply.host(), reply.process(), {reply.process()},
                   {to_nanoseconds(reply.probe_sent()), to_nanoseconds(reply.received()),
                    to_nanoseconds(reply.sent()), to_nanoseconds(to_time_msg(Clock::now()))},
                   std::chrono::steady_clock::now());
      });
    }
    const auto now = std::chrono::steady_clock::now();
    for (const auto& [process, entry] : last) {
      ProcessDiagnosticsSeen& d = seen.diagnostics.emplace_back();
      d.process = process;
      d.host = entry.first.status().front().hardware_id();
      d.age_s = std::chrono::duration<double>(now - entry.second).count();
      for (const auto& status : entry.first.status()) {
        d.statuses.push_back({status.level(), status.name(), status.message()});
      }
    }
    for (const std::string& process : [&] {
           std::set<std::string> names;
           for (const auto& d : seen.diagnostics) names.insert(d.process);
           return names;
         }()) {
      const health::PeerClocks::Peer* peer = clocks.publisher_of(process);
      if (peer == nullptr || !peer->filter.offset()) continue;
      seen.clocks.push_back({peer->process, peer->host, peer->filter.offset()->offset_ns,
                             peer->filter.offset()->round_trip_ns});
    }
    for (DiscoveredEndpoint& endpoint : transport->discovered_endpoints()) {
      if (endpoint.participant != kParticipant) seen.endpoints.push_back(std::move(endpoint));
    }
    seen.announced = announcements.get();
  } catch (const std::exception& e) {
    fmt::print(stderr, "mocap_topic doctor: {}\n", e.what());
    return 2;
  }
  bool problems = false;
  for (const Finding& finding : diagnose(seen, expected)) {
    problems = problems || finding.problem;
    fmt::print("{} {}\n", finding.problem ? "problem:" : "ok:     ", finding.text);
  }
  return problems ? 1 : 0;
}

}  // namespace mocap::doctor
