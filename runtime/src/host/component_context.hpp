// What one component sees of the process that hosts it (mocap::Context): its name,
// parameters and logger, its strand on the executor, its endpoints on every transport, its
// timers and workers. The host makes one per component and destroys it after the component.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stop_token>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <mocap/component.hpp>
#include <mocap/component_host.hpp>

#include "core/executor.hpp"
#include "core/timer_service.hpp"
#include "transport/transport.hpp"

namespace mocap {

// What a context takes from its host; the host outlives every context it makes.
struct HostServices {
  Executor& executor;
  TimerService& timers;
  // In-process first, then DDS when it is on: a publisher writes to each, a subscription takes
  // from each in turn.
  const std::vector<std::unique_ptr<Transport>>& transports;
  std::function<void(int exit_code)> request_shutdown;
  std::function<std::vector<KnownTopic>()> known_topics;
  std::function<std::vector<KnownTopic>()> discovered_topics;
  const std::string& process_name;
  std::function<std::vector<ComponentHealth>()> process_health;
};

class ComponentContext final : public Context {
 public:
  ComponentContext(HostServices& host, std::string plugin, ComponentSpec spec,
                   ComponentConfig config, Parameters parameters);
  // Stops and joins the workers, removes the timers, then the endpoints.
  ~ComponentContext() override;

  const std::string& name() const override { return config_.name; }
  const Parameters& parameters() const override { return parameters_; }
  const Logger& logger() const override { return logger_; }
  Clock::time_point now() const override { return Clock::now(); }
  std::shared_ptr<PublisherPort> advertise(std::string_view topic,
                                           const MessageType& type) override;
  std::shared_ptr<PublisherPort> advertise_any(std::string_view topic, const MessageType& type,
                                               const Qos& qos) override;
  void subscribe(std::string_view topic, const MessageType& type,
                 MessageCallback callback) override;
  void subscribe_any(std::string_view topic, const MessageType& type, const Qos& qos,
                     MessageCallback callback) override;
  void unsubscribe_any(std::string_view topic) override;
  std::vector<KnownTopic> known_topics() const override { return host_.known_topics(); }
  std::vector<KnownTopic> discovered_topics() const override { return host_.discovered_topics(); }
  void add_timer(std::chrono::nanoseconds period, std::function<void()> callback) override;
  void add_one_shot_timer(std::chrono::nanoseconds delay, std::function<void()> callback) override;
  // Started by the host once the component exists (ComponentHost::start, or add()).
  void add_worker(std::string name, std::function<void(std::stop_token)> body) override;
  void request_shutdown(int exit_code) override { host_.request_shutdown(exit_code); }
  const std::string& process_name() const override { return host_.process_name; }
  std::vector<ComponentHealth> process_health() const override { return host_.process_health(); }

  // Lets go of the transports' readers of every subscription: for a host that has stopped, so
  // that no reader of this process holds its DDS implementation's delivery up while writers go
  // (Cyclone DDS delivers into a full keep-all reader on the thread a writer's deletion waits
  // for).
  void close_subscriptions();
  // Asks `component` (this context's) for its report once a second, on its strand, from now.
  void start_health_reports(Component& component);
  // The runtime's counts and the component's last report. Thread-safe.
  ComponentHealth health() const;

  // This component's declared topics as the launch file sets them (remaps, QoS), for
  // known_topics().
  void add_declared_topics(std::map<std::string, KnownTopic>& known) const;

  Strand& strand() { return strand_; }
  void start_workers();
  void request_workers_stop();
  void join_workers();
  uint64_t worker_errors() const { return worker_errors_.load(); }

 private:
  struct Worker {
    std::string name;
    std::function<void(std::stop_token)> body;
    std::jthread thread;
  };

  std::string remapped(const std::string& topic) const;
  void check_created_off_transport_threads(const Endpoint& endpoint);
  std::shared_ptr<PublisherPort> advertise_endpoint(const Endpoint& endpoint);
  void subscribe_endpoint(const Endpoint& endpoint, MessageCallback callback);
  void add_timer(std::shared_ptr<Timer> timer);
  Endpoint resolve(std::string_view topic, const MessageType& type, TopicDirection direction);
  Endpoint resolve_any(std::string_view topic, const MessageType& type, const Qos& qos,
                       TopicDirection direction);

  HostServices& host_;
  std::string plugin_;
  ComponentSpec spec_;
  ComponentConfig config_;
  Parameters parameters_;
  Logger logger_;
  Strand strand_;
  // Changed by the component's callbacks (subscribe_any and the like), read by health().
  mutable std::mutex endpoints_mutex_;
  std::vector<std::shared_ptr<PublisherPort>> publishers_;
  std::vector<std::shared_ptr<Waitable>> waitables_;
  std::vector<std::shared_ptr<Timer>> timers_;
  std::vector<std::unique_ptr<Worker>> workers_;
  std::atomic<uint64_t> worker_errors_{0};
  mutable std::mutex report_mutex_;
  HealthReport report_;  // the last one, under report_mutex_
  std::chrono::steady_clock::time_point reported_at_{};
};

}  // namespace mocap
