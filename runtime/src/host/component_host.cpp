#include <mocap/component_host.hpp>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <stdexcept>

#include <fmt/format.h>

#include "core/executor.hpp"
#include "core/names.hpp"
#include "core/shutdown_signal.hpp"
#include "core/throttle.hpp"
#include "core/timer_service.hpp"
#include "dds/dds_transport.hpp"
#include "host/component_context.hpp"
#include "host/dds_implementations.hpp"
#include "transport/intra_process_transport.hpp"

namespace mocap {

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
  // What contexts take from the host; declared before them, so destroyed after.
  HostServices services{executor,
                        timers,
                        transports,
                        [this](int code) { request_shutdown(code); },
                        [this] { return known_topics(); },
                        [this] { return discovered_topics(); },
                        options.name,
                        [this] { return process_health(); }};
  // Declared after the transports: destroyed before them.
  std::vector<std::unique_ptr<ComponentContext>> contexts;
  mutable std::mutex contexts_mutex;  // add() against process_health() on a strand
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
  std::vector<ComponentHealth> process_health() const;
};

std::vector<ComponentHealth> ComponentHost::Impl::process_health() const {
  std::vector<ComponentHealth> health;
  std::lock_guard lock(contexts_mutex);
  for (const auto& context : contexts) health.push_back(context->health());
  return health;
}

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
  // Every reader before any writer (component_context.hpp, close_subscriptions).
  for (const auto& context : impl_->contexts) context->close_subscriptions();
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

  auto context =
      std::make_unique<ComponentContext>(impl_->services, factory.name, std::move(spec),
                                         std::move(config), Parameters(std::move(values)));
  std::unique_ptr<Component> component;
  try {
    component = factory.create(*context);
  } catch (const std::exception& e) {
    throw ComponentError(fmt::format("{} failed to start: {}", label, e.what()));
  }
  context->start_health_reports(*component);
  context->strand().enable();
  if (impl_->started) context->start_workers();
  {
    std::lock_guard lock(impl_->contexts_mutex);
    impl_->contexts.push_back(std::move(context));
  }
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
                dds.shared_memory && impl_->dds_implementation->supports(DdsFeature::kSharedMemory)
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
