#include <mocap/component_host.hpp>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "core/executor.hpp"
#include "core/names.hpp"
#include "core/shutdown_signal.hpp"
#include "core/throttle.hpp"
#include "core/timer_service.hpp"
#include "dds/dds_transport.hpp"
#include "transport/intra_process_transport.hpp"

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

  bool execute_one() override {
    ReceivedMessage received;
    for (size_t i = 0; i < sources_.size(); ++i) {
      // Round robin, so that a busy transport cannot starve another.
      size_t index = (next_ + i) % sources_.size();
      if (sources_[index]->take(received)) {
        next_ = index + 1;
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
};

}  // namespace

std::vector<std::string> check_component_config(const ComponentSpec& spec,
                                                const ComponentConfig& config) {
  std::vector<std::string> problems;
  std::vector<std::string> parameter_names;
  for (const ParameterSpec& p : spec.parameters()) parameter_names.push_back(p.name);
  for (const auto& [name, value] : config.parameters) {
    const ParameterSpec* parameter = spec.find_parameter(name);
    if (parameter == nullptr) {
      problems.push_back(fmt::format("unknown parameter '{}'{}", name,
                                     did_you_mean(name, parameter_names, "parameters")));
    } else if (auto why = parameter->check(value)) {
      problems.push_back(fmt::format("parameter '{}' {}", name, *why));
    }
  }
  std::vector<std::string> topic_names;
  for (const TopicSpec& t : spec.topics()) topic_names.push_back(t.topic);
  // A component that declares any topic may have any topic name remapped or given a QoS.
  auto declared = [&](const std::string& topic) {
    return spec.find_topic(topic) != nullptr ||
           (valid_topic_name(topic) && (spec.find_any_topic(TopicDirection::Publish) != nullptr ||
                                        spec.find_any_topic(TopicDirection::Subscribe) != nullptr));
  };
  for (const auto& [from, to] : config.remaps) {
    if (!declared(from)) {
      problems.push_back(fmt::format("remap of unknown topic '{}'{}", from,
                                     did_you_mean(from, topic_names, "topics")));
    }
    if (is_topic_family(from)) {
      // A family maps to a family with the same placeholders, in the same order.
      auto count = [](std::string_view t) { return std::count(t.begin(), t.end(), '{'); };
      if (!valid_topic_family(to) || count(to) != count(from)) {
        problems.push_back(
            fmt::format("remap target '{}' must be a topic family with {} placeholder(s) like '{}'",
                        to, count(from), from));
      }
    } else if (!valid_topic_name(to)) {
      problems.push_back(fmt::format("remap target '{}' is not a topic name (like /a/b_c)", to));
    }
  }
  for (const auto& [topic, qos] : config.qos) {
    if (!declared(topic)) {
      problems.push_back(fmt::format("QoS for unknown topic '{}'{}", topic,
                                     did_you_mean(topic, topic_names, "topics")));
    } else if (const TopicSpec* subscribed = spec.find_topic(topic);
               qos.max_blocking && subscribed != nullptr &&
               subscribed->direction == TopicDirection::Subscribe) {
      problems.push_back(
          fmt::format("QoS for '{}': max_blocking_s limits a publisher's wait, and the component "
                      "subscribes to this topic",
                      topic));
    }
  }
  return problems;
}

// ---------------------------------------------------------------------------------------

struct ComponentHost::Impl {
  class ComponentContext;

  explicit Impl(HostOptions host_options)
      : options(std::move(host_options)), executor(options.threads), logger(options.name) {
    transports.push_back(std::make_unique<IntraProcessTransport>());
    if (options.dds.enabled) {
      dds_implementation = &resolve_dds_implementation(options.dds.implementation);
      auto dds = dds_implementation->make(options.dds, options.name);
      dds_domain = dds->domain_id();
      transports.push_back(std::move(dds));
    }
  }

  void request_shutdown(int code) {
    int current = exit_code.load();
    while (code > current && !exit_code.compare_exchange_weak(current, code)) {
    }
    shutdown_requested.store(true);
    ShutdownSignal::wake();
  }

  HostOptions options;
  Executor executor;
  TimerService timers;
  Logger logger;
  std::vector<std::unique_ptr<Transport>> transports;
  int dds_domain = -1;
  const DdsImplementation* dds_implementation = nullptr;
  // Declared after the transports: destroyed before them.
  std::vector<std::unique_ptr<ComponentContext>> contexts;
  std::vector<std::unique_ptr<Component>> components;
  std::atomic<bool> shutdown_requested{false};
  std::atomic<int> exit_code{0};
  bool started = false;
  // HostOptions::health_file's writer, on a strand of its own.
  std::unique_ptr<Strand> health_strand;
  std::shared_ptr<Timer> health_timer;
  Throttle health_failures{std::chrono::seconds(60)};

  // "" or why the file could not be written.
  std::string write_health_file() const;

  std::vector<KnownTopic> known_topics() const;
  std::vector<KnownTopic> discovered_topics() const;
};

class ComponentHost::Impl::ComponentContext final : public Context {
 public:
  ComponentContext(Impl& host, ComponentSpec spec, ComponentConfig config, Parameters parameters)
      : host_(host),
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

  ~ComponentContext() override {
    request_workers_stop();
    join_workers();
    for (const auto& timer : timers_) host_.timers.remove(timer.get());
    // Transport endpoints go first, so that nothing notifies the strand once it is gone.
    strand_.clear();
    publishers_.clear();
    waitables_.clear();
  }

  const std::string& name() const override { return config_.name; }
  const Parameters& parameters() const override { return parameters_; }
  const Logger& logger() const override { return logger_; }
  Clock::time_point now() const override { return Clock::now(); }

  std::shared_ptr<PublisherPort> advertise(std::string_view topic,
                                           const MessageType& type) override {
    return advertise_endpoint(resolve(topic, type, TopicDirection::Publish));
  }

  std::shared_ptr<PublisherPort> advertise_any(std::string_view topic, const MessageType& type,
                                               const Qos& qos) override {
    return advertise_endpoint(resolve_any(topic, type, qos, TopicDirection::Publish));
  }

  void subscribe(std::string_view topic, const MessageType& type,
                 MessageCallback callback) override {
    subscribe_endpoint(resolve(topic, type, TopicDirection::Subscribe), std::move(callback));
  }

  void subscribe_any(std::string_view topic, const MessageType& type, const Qos& qos,
                     MessageCallback callback) override {
    subscribe_endpoint(resolve_any(topic, type, qos, TopicDirection::Subscribe),
                       std::move(callback));
  }

  void unsubscribe_any(std::string_view topic) override {
    const std::string name = remapped(std::string(topic));
    std::erase_if(waitables_, [&](const std::shared_ptr<Waitable>& waitable) {
      auto* subscription = dynamic_cast<HostSubscription*>(waitable.get());
      if (subscription == nullptr || subscription->topic() != name) return false;
      subscription->sources_.clear();  // the transports' readers go now
      strand_.remove(subscription);
      return true;
    });
  }

  std::vector<KnownTopic> known_topics() const override { return host_.known_topics(); }
  std::vector<KnownTopic> discovered_topics() const override { return host_.discovered_topics(); }

  // This component's declared topics as the launch file sets them (remaps, QoS), for
  // known_topics().
  void add_declared_topics(std::map<std::string, KnownTopic>& known) const {
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

 private:
  std::string remapped(const std::string& topic) const {
    auto it = config_.remaps.find(topic);
    return it == config_.remaps.end() ? topic : it->second;
  }

  // A component declared with publishes_any / subscribes_any runs its callbacks on the
  // executor; one that creates a declared endpoint in a callback does so from then on, and
  // must not have done it on a transport's thread (Strand::keep_off_transport_threads).
  void check_created_off_transport_threads(const Endpoint& endpoint) {
    if (Strand::on_transport_thread()) {
      throw std::logic_error(fmt::format(
          "{} for {} created in a callback run on a DDS thread: a component that creates "
          "publishers or subscriptions in its callbacks declares publishes_any or subscribes_any",
          endpoint.owner, endpoint.topic));
    }
    if (strand_.enabled()) strand_.keep_off_transport_threads();
  }

  std::shared_ptr<PublisherPort> advertise_endpoint(const Endpoint& endpoint) {
    check_created_off_transport_threads(endpoint);
    if (publisher_may_wait(endpoint.qos, Qos::reliable())) strand_.keep_off_transport_threads();
    auto publisher = std::make_shared<HostPublisher>(endpoint.topic);
    for (auto& transport : host_.transports) {
      publisher->ports_.push_back(transport->advertise(endpoint));
    }
    publishers_.push_back(publisher);
    return publisher;
  }

  void subscribe_endpoint(const Endpoint& endpoint, MessageCallback callback) {
    check_created_off_transport_threads(endpoint);
    auto subscription = std::make_shared<HostSubscription>(endpoint.topic, std::move(callback));
    for (auto& transport : host_.transports) {
      subscription->sources_.push_back(
          transport->subscribe(endpoint, [strand = &strand_](bool may_run_callbacks) {
            may_run_callbacks ? strand->dispatch() : strand->notify();
          }));
    }
    waitables_.push_back(subscription);
    strand_.add(subscription);
  }

 public:
  void add_timer(std::chrono::nanoseconds period, std::function<void()> callback) override {
    if (period <= std::chrono::nanoseconds::zero()) {
      throw std::invalid_argument(
          fmt::format("timer period must be positive, got {} ns", period.count()));
    }
    add_timer(std::make_shared<Timer>("timer every " + format_period(period), period,
                                      std::move(callback), strand_));
  }

  void add_one_shot_timer(std::chrono::nanoseconds delay, std::function<void()> callback) override {
    add_timer(std::make_shared<Timer>("timer after " + format_period(delay),
                                      std::max(delay, std::chrono::nanoseconds(1)),
                                      std::move(callback), strand_, Timer::Repeat::Once));
  }

  void add_worker(std::string name, std::function<void(std::stop_token)> body) override {
    // Started by the host once the component exists (ComponentHost::start, or add()).
    workers_.push_back(std::make_unique<Worker>(Worker{std::move(name), std::move(body), {}}));
  }

  void request_shutdown(int exit_code) override { host_.request_shutdown(exit_code); }

  Strand& strand() { return strand_; }

  void start_workers() {
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
  void request_workers_stop() {
    for (auto& worker : workers_) worker->thread.request_stop();
  }
  void join_workers() {
    for (auto& worker : workers_) {
      if (worker->thread.joinable()) worker->thread.join();
    }
  }
  uint64_t worker_errors() const { return worker_errors_.load(); }

 private:
  void add_timer(std::shared_ptr<Timer> timer) {
    timers_.push_back(timer);
    waitables_.push_back(timer);
    strand_.add(timer);
    host_.timers.add(timer);
  }

  Endpoint resolve(std::string_view topic, const MessageType& type, TopicDirection direction) {
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
  Endpoint resolve_any(std::string_view topic, const MessageType& type, const Qos& qos,
                       TopicDirection direction) {
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

  Impl& host_;
  ComponentSpec spec_;
  ComponentConfig config_;
  Parameters parameters_;
  Logger logger_;
  Strand strand_;
  std::vector<std::shared_ptr<HostPublisher>> publishers_;
  std::vector<std::shared_ptr<Waitable>> waitables_;
  std::vector<std::shared_ptr<Timer>> timers_;
  struct Worker {
    std::string name;
    std::function<void(std::stop_token)> body;
    std::jthread thread;
  };
  std::vector<std::unique_ptr<Worker>> workers_;
  std::atomic<uint64_t> worker_errors_{0};
};

// ---------------------------------------------------------------------------------------

std::vector<KnownTopic> ComponentHost::Impl::known_topics() const {
  std::map<std::string, KnownTopic> known;
  for (const KnownTopic& topic : options.known_topics) {
    KnownTopic& merged = known[topic.topic];
    if (merged.type == nullptr) {
      merged.topic = topic.topic;
      merged.type = topic.type;
    }
    merged.publishers.insert(merged.publishers.end(), topic.publishers.begin(),
                             topic.publishers.end());
  }
  // The launch file's list already holds this process's components; only a host built by
  // hand (tests, benchmarks) needs theirs added.
  if (options.known_topics.empty()) {
    for (const auto& context : contexts) context->add_declared_topics(known);
  }
  std::vector<KnownTopic> topics;
  for (auto& [name, topic] : known) topics.push_back(std::move(topic));
  return topics;
}

std::vector<KnownTopic> ComponentHost::Impl::discovered_topics() const {
  std::map<std::string, KnownTopic> discovered;
  for (const auto& transport : transports) {
    const auto* dds = dynamic_cast<const DdsTransport*>(transport.get());
    if (dds == nullptr) continue;
    for (const DiscoveredEndpoint& endpoint : dds->discovered_endpoints()) {
      if (!endpoint.is_publisher || !valid_topic_name(endpoint.topic)) continue;
      const MessageType* type = find_message_type(endpoint.type);
      if (type == nullptr) continue;
      KnownTopic& topic = discovered[endpoint.topic];
      if (topic.type != nullptr && topic.type != type) continue;  // one type per topic: the first
      topic.topic = endpoint.topic;
      topic.type = type;
      topic.publishers.push_back(endpoint.qos);
    }
  }
  std::vector<KnownTopic> topics;
  for (auto& [name, topic] : discovered) topics.push_back(std::move(topic));
  return topics;
}

ComponentHost::ComponentHost(HostOptions options)
    : impl_(std::make_unique<Impl>(std::move(options))) {}

ComponentHost::~ComponentHost() {
  stop();
  while (!impl_->components.empty()) {
    impl_->components.pop_back();
    impl_->contexts.pop_back();
  }
}

Component& ComponentHost::add(const ComponentFactory& factory, ComponentConfig config) {
  ComponentSpec spec;
  factory.declare(spec);
  std::string label = fmt::format("component '{}' ({})", config.name, factory.name);
  if (!valid_component_name(config.name)) {
    throw ComponentError(fmt::format("{}: names use letters, digits, '_' and '-'", label));
  }
  for (const auto& context : impl_->contexts) {
    if (context->name() == config.name) throw ComponentError(label + ": the name is taken");
  }
  std::vector<std::string> problems = check_component_config(spec, config);
  if (!problems.empty()) {
    throw ComponentError(fmt::format("{}: {}", label, fmt::join(problems, "; ")));
  }

  std::map<std::string, ParameterValue, std::less<>> values;
  for (const ParameterSpec& parameter : spec.parameters()) {
    auto given = config.parameters.find(parameter.name);
    values[parameter.name] = given == config.parameters.end() ? parameter.default_value
                                                              : parameter.coerce(given->second);
  }

  auto context = std::make_unique<Impl::ComponentContext>(
      *impl_, std::move(spec), std::move(config), Parameters(std::move(values)));
  std::unique_ptr<Component> component;
  try {
    component = factory.create(*context);
  } catch (const std::exception& e) {
    throw ComponentError(fmt::format("{} failed to start: {}", label, e.what()));
  }
  context->strand().enable();
  if (impl_->started) context->start_workers();
  impl_->contexts.push_back(std::move(context));
  impl_->components.push_back(std::move(component));
  return *impl_->components.back();
}

std::string ComponentHost::Impl::write_health_file() const {
  // Written beside and renamed: a reader never sees half a file.
  std::string partial = options.health_file + ".partial";
  std::ofstream out(partial, std::ios::trunc);
  out << fmt::format("{} alive at {}\n", options.name,
                     std::chrono::duration_cast<std::chrono::seconds>(
                         std::chrono::system_clock::now().time_since_epoch())
                         .count());
  out.close();
  if (!out)
    return fmt::format("cannot write the health file {}: cannot write {}", options.health_file,
                       partial);
  std::error_code error;
  std::filesystem::rename(partial, options.health_file, error);
  if (error) {
    return fmt::format("cannot write the health file {}: {}", options.health_file, error.message());
  }
  return {};
}

void ComponentHost::start() {
  if (impl_->started) return;
  impl_->started = true;
  if (!impl_->options.health_file.empty()) {
    if (std::string error = impl_->write_health_file(); !error.empty()) {
      impl_->started = false;
      throw std::runtime_error(error);
    }
    impl_->health_strand = std::make_unique<Strand>(impl_->executor, impl_->logger);
    impl_->health_timer = std::make_shared<Timer>(
        "health file", std::chrono::seconds(1),
        [impl = impl_.get()] {
          // Later failures (a full disk) leave the file to age: the HEALTHCHECK then says so.
          if (std::string error = impl->write_health_file(); !error.empty()) {
            if (auto times = impl->health_failures.count()) {
              impl->logger.warn("{} ({} time(s) since the last report)", error, *times);
            }
          }
        },
        *impl_->health_strand);
    impl_->health_strand->add(impl_->health_timer);
    impl_->health_strand->enable();
    impl_->timers.add(impl_->health_timer);
  }
  impl_->executor.start();
  impl_->timers.start();
  for (const auto& context : impl_->contexts) context->start_workers();
}

int ComponentHost::run(std::optional<std::chrono::duration<double>> duration) {
  ShutdownSignal::install();
  start();
  std::vector<std::string> names;
  for (const auto& context : impl_->contexts) names.push_back(context->name());
  const DdsOptions& dds = impl_->options.dds;
  impl_->logger.info(
      "running {} on {} thread(s); {}", fmt::join(names, ", "), impl_->executor.threads(),
      dds.enabled
          ? fmt::format(
                "{} DDS domain {}{}", impl_->dds_implementation->name, impl_->dds_domain,
                dds.fastdds.shared_memory && impl_->dds_implementation->takes_fastdds_options
                    ? ""
                    : ", UDP only")
          : std::string("DDS off"));
  if (dds.enabled) {
    if (auto problem = udp_buffer_problem()) impl_->logger.warn("{}", *problem);
  }
  auto deadline =
      duration ? std::chrono::steady_clock::now() +
                     std::chrono::duration_cast<std::chrono::steady_clock::duration>(*duration)
               : std::chrono::steady_clock::time_point::max();
  while (!impl_->shutdown_requested.load()) {
    std::optional<std::chrono::steady_clock::duration> left;
    if (duration) {
      left = deadline - std::chrono::steady_clock::now();
      if (*left <= std::chrono::steady_clock::duration::zero()) break;
    }
    if (ShutdownSignal::wait(left)) {
      impl_->logger.info("shutting down on signal");
      break;
    }
  }
  stop();
  return impl_->exit_code.load();
}

void ComponentHost::stop() {
  impl_->timers.stop();
  for (const auto& context : impl_->contexts) context->request_workers_stop();
  // Callbacks and workers waiting for a subscriber's room would hold the stop up forever: the
  // subscribers in this process no longer run, those in others may not catch up.
  for (auto& transport : impl_->transports) transport->stop_waiting();
  // Workers first: they may still publish, and components are destroyed only after this.
  for (const auto& context : impl_->contexts) context->join_workers();
  impl_->executor.stop();
}

uint64_t ComponentHost::callback_errors() const {
  uint64_t errors = 0;
  for (const auto& context : impl_->contexts) {
    errors += context->strand().callback_errors() + context->worker_errors();
  }
  return errors;
}

const HostOptions& ComponentHost::options() const { return impl_->options; }

}  // namespace mocap
