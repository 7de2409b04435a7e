#include "host/component_context.hpp"

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/names.hpp"

namespace mocap {

bool wait_for_stop(const std::stop_token& stop, std::chrono::nanoseconds duration) {
  std::mutex mutex;
  std::condition_variable_any woken;
  std::unique_lock lock(mutex);
  woken.wait_for(lock, stop, duration, [] { return false; });
  return !stop.stop_requested();
}

namespace {

std::string format_period(std::chrono::nanoseconds period) {
  double seconds = std::chrono::duration<double>(period).count();
  if (seconds >= 1.0) return fmt::format("{:g} s", seconds);
  if (seconds >= 1e-3) return fmt::format("{:g} ms", seconds * 1e3);
  return fmt::format("{:g} us", seconds * 1e6);
}

std::string declared_topics(const ComponentSpec& spec) {
  std::vector<std::string> names;
  for (const TopicSpec& topic : spec.topics()) names.push_back(topic.topic);
  return names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "));
}

// A publisher as components see it: one port per transport.
class HostPublisher final : public PublisherPort {
 public:
  explicit HostPublisher(std::string topic) : topic_(std::move(topic)) {}

  void publish(std::shared_ptr<const void> message) override {
    if (message == nullptr) throw std::invalid_argument("publish() of a null message on " + topic_);
    Clock::time_point now = Clock::now();
    published_.fetch_add(1, std::memory_order_relaxed);
    for (auto& port : ports_) port->publish(message, now);
  }

  size_t matched_subscribers() const override {
    size_t count = 0;
    for (const auto& port : ports_) count += port->matched_subscribers();
    return count;
  }

  const std::string& topic() const override { return topic_; }

  PublisherStats stats() const override {
    PublisherStats total;
    total.published = published_.load(std::memory_order_relaxed);
    for (const auto& port : ports_) {
      PublisherStats stats = port->stats();
      total.waited += stats.waited;
      total.blocked += stats.blocked;
      total.longest_wait = std::max(total.longest_wait, stats.longest_wait);
      total.dropped += stats.dropped;
    }
    return total;
  }

  std::vector<std::unique_ptr<TransportPublisher>> ports_;

 private:
  std::string topic_;
  std::atomic<uint64_t> published_{0};
};

// A subscription as the executor sees it: takes from every transport in turn.
class HostSubscription final : public Waitable {
 public:
  HostSubscription(std::string topic, MessageCallback callback)
      : Waitable("subscription to " + topic),
        topic_(std::move(topic)),
        callback_(std::move(callback)) {}

  const std::string& topic() const { return topic_; }
  uint64_t received() const { return received_.load(std::memory_order_relaxed); }
  // Over every transport; call with the context's endpoints_mutex_ held (sources_ changes under
  // it).
  TopicCounts counts() const {
    TopicCounts counts{topic_, received(), 0, std::nullopt};
    for (const auto& source : sources_) {
      counts.dropped += source->dropped();
      if (auto waiting = source->waiting()) counts.waiting = counts.waiting.value_or(0) + *waiting;
    }
    return counts;
  }

  bool execute_one() override {
    ReceivedMessage received;
    for (size_t i = 0; i < sources_.size(); ++i) {
      // Round robin, so that a busy transport cannot starve another.
      size_t index = (next_ + i) % sources_.size();
      if (sources_[index]->take(received)) {
        next_ = index + 1;
        received_.fetch_add(1, std::memory_order_relaxed);
        run_callback([&] { callback_(received.message); });
        return true;
      }
    }
    return false;
  }

  // None once unsubscribed: it runs nothing more.
  std::vector<std::unique_ptr<TransportSubscription>> sources_;

 private:
  std::string topic_;  // after remaps
  MessageCallback callback_;
  size_t next_ = 0;
  std::atomic<uint64_t> received_{0};
};

}  // namespace

ComponentContext::ComponentContext(HostServices& host, std::string plugin, ComponentSpec spec,
                                   ComponentConfig config, Parameters parameters)
    : host_(host),
      plugin_(std::move(plugin)),
      spec_(std::move(spec)),
      config_(std::move(config)),
      parameters_(std::move(parameters)),
      logger_(config_.name),
      strand_(host.executor, logger_) {
  if (spec_.find_any_topic(TopicDirection::Publish) != nullptr ||
      spec_.find_any_topic(TopicDirection::Subscribe) != nullptr) {
    strand_.keep_off_transport_threads();  // creates endpoints in its callbacks
  }
}

ComponentContext::~ComponentContext() {
  request_workers_stop();
  join_workers();
  for (const auto& timer : timers_) host_.timers.remove(timer.get());
  // Transport endpoints go first, so that nothing notifies the strand once it is gone.
  strand_.clear();
  std::lock_guard lock(endpoints_mutex_);
  publishers_.clear();
  waitables_.clear();
}

std::shared_ptr<PublisherPort> ComponentContext::advertise(std::string_view topic,
                                                           const MessageType& type) {
  return advertise_endpoint(resolve(topic, type, TopicDirection::Publish));
}

std::shared_ptr<PublisherPort> ComponentContext::advertise_any(std::string_view topic,
                                                               const MessageType& type,
                                                               const Qos& qos) {
  return advertise_endpoint(resolve_any(topic, type, qos, TopicDirection::Publish));
}

void ComponentContext::subscribe(std::string_view topic, const MessageType& type,
                                 MessageCallback callback) {
  subscribe_endpoint(resolve(topic, type, TopicDirection::Subscribe), std::move(callback));
}

void ComponentContext::subscribe_any(std::string_view topic, const MessageType& type,
                                     const Qos& qos, MessageCallback callback) {
  subscribe_endpoint(resolve_any(topic, type, qos, TopicDirection::Subscribe), std::move(callback));
}

void ComponentContext::unsubscribe_any(std::string_view topic) {
  const std::string name = remapped(std::string(topic));
  std::lock_guard lock(endpoints_mutex_);
  std::erase_if(waitables_, [&](const std::shared_ptr<Waitable>& waitable) {
    auto* subscription = dynamic_cast<HostSubscription*>(waitable.get());
    if (subscription == nullptr || subscription->topic() != name) return false;
    subscription->sources_.clear();  // the transports' readers go now
    strand_.remove(subscription);
    return true;
  });
}

void ComponentContext::close_subscriptions() {
  std::lock_guard lock(endpoints_mutex_);
  for (const auto& waitable : waitables_) {
    if (auto* subscription = dynamic_cast<HostSubscription*>(waitable.get())) {
      subscription->sources_.clear();
    }
  }
}

void ComponentContext::start_health_reports(Component& component) {
  add_timer(std::make_shared<Timer>(
      "health report", std::chrono::seconds(1),
      [this, &component] {
        HealthReport report;
        component.report_health(report);
        std::lock_guard lock(report_mutex_);
        report_ = std::move(report);
        reported_at_ = std::chrono::steady_clock::now();
      },
      strand_));
}

ComponentHealth ComponentContext::health() const {
  ComponentHealth health;
  health.name = config_.name;
  health.plugin = plugin_;
  std::lock_guard endpoints_lock(endpoints_mutex_);
  for (const auto& publisher : publishers_) {
    PublisherStats stats = publisher->stats();
    health.published.push_back({publisher->topic(), stats.published, stats.dropped});
  }
  for (const auto& waitable : waitables_) {
    if (const auto* subscription = dynamic_cast<const HostSubscription*>(waitable.get())) {
      health.received.push_back(subscription->counts());
    }
  }
  health.callback_errors = strand_.callback_errors() + worker_errors_.load();
  std::lock_guard report_lock(report_mutex_);
  health.report = report_;
  health.reported_at = reported_at_;
  return health;
}

void ComponentContext::add_declared_topics(std::map<std::string, KnownTopic>& known) const {
  for (const TopicSpec& declared : spec_.topics()) {
    if (declared.type == nullptr) continue;
    KnownTopic& topic = known[remapped(declared.topic)];
    if (topic.type == nullptr) {
      topic.topic = remapped(declared.topic);
      topic.type = declared.type;
    }
    if (declared.direction == TopicDirection::Publish) {
      auto qos = config_.qos.find(declared.topic);
      topic.publishers.push_back(qos == config_.qos.end() ? declared.qos : qos->second);
    }
  }
}

std::string ComponentContext::remapped(const std::string& topic) const {
  auto it = config_.remaps.find(topic);
  return it == config_.remaps.end() ? topic : it->second;
}

// A component declared with publishes_any / subscribes_any runs its callbacks on the
// executor; one that creates a declared endpoint in a callback does so from then on, and
// must not have done it on a transport's thread (Strand::keep_off_transport_threads).
void ComponentContext::check_created_off_transport_threads(const Endpoint& endpoint) {
  if (Strand::on_transport_thread()) {
    throw std::logic_error(fmt::format(
        "{} for {} created in a callback run on a DDS thread: a component that creates "
        "publishers or subscriptions in its callbacks declares publishes_any or subscribes_any",
        endpoint.owner, endpoint.topic));
  }
  if (strand_.enabled()) strand_.keep_off_transport_threads();
}

std::shared_ptr<PublisherPort> ComponentContext::advertise_endpoint(const Endpoint& endpoint) {
  check_created_off_transport_threads(endpoint);
  if (publisher_may_wait(endpoint.qos, Qos::reliable())) strand_.keep_off_transport_threads();
  auto publisher = std::make_shared<HostPublisher>(endpoint.topic);
  for (auto& transport : host_.transports) {
    publisher->ports_.push_back(transport->advertise(endpoint));
  }
  std::lock_guard lock(endpoints_mutex_);
  publishers_.push_back(publisher);
  return publisher;
}

void ComponentContext::subscribe_endpoint(const Endpoint& endpoint, MessageCallback callback) {
  check_created_off_transport_threads(endpoint);
  auto subscription = std::make_shared<HostSubscription>(endpoint.topic, std::move(callback));
  for (auto& transport : host_.transports) {
    subscription->sources_.push_back(
        transport->subscribe(endpoint, [strand = &strand_](bool may_run_callbacks) {
          may_run_callbacks ? strand->dispatch() : strand->notify();
        }));
  }
  {
    std::lock_guard lock(endpoints_mutex_);
    waitables_.push_back(subscription);
  }
  strand_.add(subscription);
}

void ComponentContext::add_timer(std::chrono::nanoseconds period, std::function<void()> callback) {
  if (period <= std::chrono::nanoseconds::zero()) {
    throw std::invalid_argument(
        fmt::format("timer period must be positive, got {} ns", period.count()));
  }
  add_timer(std::make_shared<Timer>("timer every " + format_period(period), period,
                                    std::move(callback), strand_));
}

void ComponentContext::add_one_shot_timer(std::chrono::nanoseconds delay,
                                          std::function<void()> callback) {
  add_timer(std::make_shared<Timer>("timer after " + format_period(delay),
                                    std::max(delay, std::chrono::nanoseconds(1)),
                                    std::move(callback), strand_, Timer::Repeat::Once));
}

void ComponentContext::add_worker(std::string name, std::function<void(std::stop_token)> body) {
  workers_.push_back(std::make_unique<Worker>(Worker{std::move(name), std::move(body), {}}));
}

void ComponentContext::start_workers() {
  for (auto& worker : workers_) {
    if (worker->thread.joinable()) continue;
    worker->thread = std::jthread([this, worker = worker.get()](std::stop_token stop) {
      try {
        worker->body(stop);
      } catch (const std::exception& e) {
        worker_errors_.fetch_add(1);
        logger_.error("worker '{}' ended: {}", worker->name, e.what());
      }
    });
  }
}
void ComponentContext::request_workers_stop() {
  for (auto& worker : workers_) worker->thread.request_stop();
}
void ComponentContext::join_workers() {
  for (auto& worker : workers_) {
    if (worker->thread.joinable()) worker->thread.join();
  }
}

void ComponentContext::add_timer(std::shared_ptr<Timer> timer) {
  timers_.push_back(timer);
  {
    std::lock_guard lock(endpoints_mutex_);
    waitables_.push_back(timer);
  }
  strand_.add(timer);
  host_.timers.add(timer);
}

Endpoint ComponentContext::resolve(std::string_view topic, const MessageType& type,
                                   TopicDirection direction) {
  const TopicSpec* declared = spec_.find_topic(topic);
  // A topic of a declared family: its placeholders' values carry over to a remap.
  std::optional<std::vector<std::string>> family_values;
  for (const TopicSpec& t : spec_.topics()) {
    if (declared != nullptr || !is_topic_family(t.topic)) continue;
    if ((family_values = match_topic_family(t.topic, topic))) declared = &t;
  }
  std::string_view verb = direction == TopicDirection::Publish ? "publishes" : "subscribes";
  if (declared == nullptr) {
    throw std::logic_error(
        fmt::format("component '{}' {} to '{}', which its declare() does not "
                    "declare (declared: {})",
                    config_.name, verb, topic, declared_topics(spec_)));
  }
  if (declared->type != &type || declared->direction != direction) {
    throw std::logic_error(
        fmt::format("component '{}' {} to '{}' with {}, but declares it as {} ({})", config_.name,
                    verb, topic, type.name(), declared->type->name(),
                    declared->direction == TopicDirection::Publish ? "published" : "subscribed"));
  }
  Endpoint endpoint{std::string(topic), &type, declared->qos, config_.name};
  if (auto it = config_.remaps.find(declared->topic); it != config_.remaps.end()) {
    endpoint.topic =
        family_values ? instantiate_topic_family(it->second, *family_values) : it->second;
  }
  if (auto it = config_.qos.find(declared->topic); it != config_.qos.end()) {
    endpoint.qos = it->second;
  }
  return endpoint;
}

// A topic under an any-topic declaration: the caller's type and QoS, the launch file's
// remap and QoS override of that very name.
Endpoint ComponentContext::resolve_any(std::string_view topic, const MessageType& type,
                                       const Qos& qos, TopicDirection direction) {
  std::string_view verb = direction == TopicDirection::Publish ? "publishes" : "subscribes";
  if (spec_.find_any_topic(direction) == nullptr) {
    throw std::logic_error(
        fmt::format("component '{}' {} to '{}' as any topic, but its "
                    "declare() does not declare {}_any",
                    config_.name, verb, topic, verb));
  }
  if (!valid_topic_name(topic)) {
    throw std::invalid_argument(
        fmt::format("component '{}' {} to '{}', which is not a topic name (like /a/b_c)",
                    config_.name, verb, topic));
  }
  const std::string name(topic);
  Endpoint endpoint{remapped(name), &type, qos, config_.name};
  if (auto it = config_.qos.find(name); it != config_.qos.end()) endpoint.qos = it->second;
  return endpoint;
}

}  // namespace mocap
