// The component API: everything a plugin needs, and the one macro that registers it.
//
//   class Doubler final : public mocap::Component {
//    public:
//     static void declare(mocap::ComponentSpec& spec);   // parameters and topics
//     explicit Doubler(mocap::Context& context) : Component(context) {
//       output_ = create_publisher<Msg>("/out");
//       create_subscription<Msg>("/in", [this](const Msg& in) { output_.publish(twice(in)); });
//     }
//    private:
//     mocap::Publisher<Msg> output_;
//   };
//   MOCAP_REGISTER_COMPONENT(Doubler, "doubler")
//
// A component's callbacks never run concurrently with each other, so a component needs no
// locks of its own; different components run in parallel on the executor's threads. A
// component does not know whether its peers are in its process, another process or another
// host: topics are delivered in-process by pointer and to other processes over DDS.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <stop_token>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <mocap/component_spec.hpp>
#include <mocap/health.hpp>
#include <mocap/logger.hpp>
#include <mocap/message_type.hpp>
#include <mocap/parameter.hpp>
#include <mocap/parameter_list.hpp>
#include <mocap/qos.hpp>

namespace mocap {

using Clock = std::chrono::system_clock;

// What a publisher has been through. A reliable keep-all publisher waits for a subscriber
// that is `depth` samples behind (Qos::max_blocking), inside publish(): that is how a slow
// subscriber holds its producer back without losing samples.
struct PublisherStats {
  uint64_t published = 0;  // publish() calls
  // Samples that had to wait for room at some subscriber, and the time publish() spent so.
  uint64_t waited = 0;
  std::chrono::nanoseconds blocked{0};
  std::chrono::nanoseconds longest_wait{0};
  // Samples given up for some subscriber: Qos::max_blocking passed, a DDS write failed, or
  // the process was stopping. Keep-last overflow is counted by the subscriber, not here.
  uint64_t dropped = 0;
};

// The runtime side of a publisher.
class PublisherPort {
 public:
  virtual ~PublisherPort() = default;
  virtual void publish(std::shared_ptr<const void> message) = 0;
  // Matched subscriptions in this process and in others.
  virtual size_t matched_subscribers() const = 0;
  // The topic after remapping.
  virtual const std::string& topic() const = 0;
  virtual PublisherStats stats() const = 0;
};

template <class Message>
class Publisher {
 public:
  Publisher() = default;

  // In-process subscribers receive this very pointer; other processes a serialized copy.
  void publish(std::shared_ptr<const Message> message) const { port_->publish(std::move(message)); }
  void publish(Message message) const {
    publish(std::make_shared<const Message>(std::move(message)));
  }
  size_t matched_subscribers() const { return port_->matched_subscribers(); }
  const std::string& topic() const { return port_->topic(); }
  PublisherStats stats() const { return port_->stats(); }
  explicit operator bool() const { return port_ != nullptr; }

 private:
  friend class Component;
  explicit Publisher(std::shared_ptr<PublisherPort> port) : port_(std::move(port)) {}
  std::shared_ptr<PublisherPort> port_;
};

using MessageCallback = std::function<void(const std::shared_ptr<const void>&)>;

// A topic of the deployment whose type is declared: for components that pick topics at run
// time (a recorder, a player).
struct KnownTopic {
  std::string topic;  // as used, after remaps; a family keeps its placeholders: /a/{name}/b
  const MessageType* type = nullptr;
  std::vector<Qos> publishers;  // the QoS each declared publisher offers
};

// What the runtime gives a component. Topic names passed here are the declared ones; the
// context applies the launch file's remaps and QoS overrides.
class Context {
 public:
  virtual ~Context() = default;
  virtual const std::string& name() const = 0;
  virtual const Parameters& parameters() const = 0;
  virtual const Logger& logger() const = 0;
  virtual Clock::time_point now() const = 0;
  virtual std::shared_ptr<PublisherPort> advertise(std::string_view topic,
                                                   const MessageType& type) = 0;
  virtual void subscribe(std::string_view topic, const MessageType& type,
                         MessageCallback callback) = 0;
  // For components declared with publishes_any / subscribes_any: a topic, type and QoS
  // chosen at run time (the launch file's remap and QoS override of that topic still apply).
  virtual std::shared_ptr<PublisherPort> advertise_any(std::string_view topic,
                                                       const MessageType& type, const Qos& qos) = 0;
  virtual void subscribe_any(std::string_view topic, const MessageType& type, const Qos& qos,
                             MessageCallback callback) = 0;
  // Ends what subscribe_any started on `topic` (the name given to it): no more of its messages
  // reach the callbacks, those waiting are dropped, and the transports stop receiving it, so
  // that other processes see the subscriber go and stop sending. For components that follow
  // what their users ask for (a viewer). A topic not subscribed to is no error.
  virtual void unsubscribe_any(std::string_view topic) = 0;
  // The topics the launch file's components declare, in every group, with their types.
  virtual std::vector<KnownTopic> known_topics() const = 0;
  // The topics other processes on the DDS domain publish right now, with the QoS their
  // publishers announce, whose types this process knows (shipped and loaded message
  // libraries): for components that follow the graph as it changes (a viewer). Other
  // processes' topics disappear once their publishers leave. Empty without DDS.
  virtual std::vector<KnownTopic> discovered_topics() const = 0;
  virtual void add_timer(std::chrono::nanoseconds period, std::function<void()> callback) = 0;
  virtual void add_one_shot_timer(std::chrono::nanoseconds delay,
                                  std::function<void()> callback) = 0;
  virtual void add_worker(std::string name, std::function<void(std::stop_token)> body) = 0;
  // Ends the process's run once the current callbacks return; the process exits with
  // `exit_code` (the largest requested, if several components ask).
  virtual void request_shutdown(int exit_code) = 0;
  // The name of this process: its launch-file group, or the host's name given by hand.
  virtual const std::string& process_name() const = 0;
  // Every component of this process: what the runtime counts and its last report_health(), for
  // a component that publishes them (diagnostics).
  virtual std::vector<ComponentHealth> process_health() const = 0;
};

class Component {
 public:
  explicit Component(Context& context) : context_(context) {}
  virtual ~Component() = default;
  Component(const Component&) = delete;
  Component& operator=(const Component&) = delete;

  const std::string& name() const { return context_.name(); }

  // Called once a second on the component's strand (never beside its callbacks), from the
  // moment the process runs: how the component is doing, for /diagnostics (mocap/health.hpp).
  // The runtime adds its own counts of messages, drops and callback errors; a component adds
  // what only it knows (rates against what it expects, its stage's latency, causes) and flags
  // problems with a sentence that says what to do.
  virtual void report_health(HealthReport& report) { (void)report; }

 protected:
  template <class Message>
  Publisher<Message> create_publisher(std::string_view topic) {
    return Publisher<Message>(context_.advertise(topic, message_type<Message>()));
  }

  // `callback` takes `const Message&` or `const std::shared_ptr<const Message>&`; keep the
  // shared pointer to hold on to a message without copying it.
  template <class Message, class Callback>
  void create_subscription(std::string_view topic, Callback&& callback) {
    context_.subscribe(
        topic, message_type<Message>(),
        [cb = std::forward<Callback>(callback)](const std::shared_ptr<const void>& m) {
          auto typed = std::static_pointer_cast<const Message>(m);
          if constexpr (std::is_invocable_v<Callback&, const std::shared_ptr<const Message>&>) {
            cb(typed);
          } else {
            cb(*typed);
          }
        });
  }

  // Runs `callback` every `period` (steady clock). Late ticks are not queued: a callback
  // slower than its period runs back to back, not in a burst.
  template <class Callback>
  void create_timer(std::chrono::nanoseconds period, Callback&& callback) {
    context_.add_timer(period, std::forward<Callback>(callback));
  }
  // Runs `callback` once, `delay` after the process starts (after this call, if it runs).
  template <class Callback>
  void create_one_shot_timer(std::chrono::nanoseconds delay, Callback&& callback) {
    context_.add_one_shot_timer(delay, std::forward<Callback>(callback));
  }

  // Runs `body` on a thread of its own, for work that blocks (a serial port, a capture device,
  // a file played at its pace). The host starts it with the timers, once every component of
  // the process exists, and when the process stops it requests the stop (`body`'s token) and
  // joins the thread before any component is destroyed: a body checks the token at least as
  // often as the host should wait for it (a read with a timeout; wait_for_stop to sleep). An
  // exception ends the worker; it is logged with the component's name and counted as a
  // callback error. Unlike callbacks, a worker runs beside the component's callbacks: what
  // both touch needs a lock.
  void create_worker(std::string name, std::function<void(std::stop_token)> body) {
    context_.add_worker(std::move(name), std::move(body));
  }

  // The settings `parameters` bind, from this instance's values (the launch file's, or the
  // defaults): what the component's declare() gave ParameterList::declare.
  template <class Settings>
  Settings read_settings(const ParameterList<Settings>& parameters) const {
    return parameters.read(context_.parameters());
  }
  const Logger& log() const { return context_.logger(); }
  Clock::time_point now() const { return context_.now(); }
  void request_shutdown(int exit_code = 0) { context_.request_shutdown(exit_code); }
  Context& context() const { return context_; }

 private:
  Context& context_;
};

// Sleeps for `duration` or until `stop` is requested; false if it was (a worker's pause).
bool wait_for_stop(const std::stop_token& stop, std::chrono::nanoseconds duration);

// What a plugin library exports, through MOCAP_REGISTER_COMPONENT.
struct ComponentFactory {
  // Raised whenever Component, Context or this struct change layout.
  static constexpr uint32_t kAbiVersion = 6;
  static constexpr const char* kSymbol = "mocap_component_factory";

  uint32_t abi_version;
  const char* name;
  void (*declare)(ComponentSpec& spec);
  std::unique_ptr<Component> (*create)(Context& context);
};

template <class ComponentClass>
constexpr ComponentFactory make_component_factory(const char* name) {
  static_assert(std::is_base_of_v<Component, ComponentClass>, "components derive mocap::Component");
  return {ComponentFactory::kAbiVersion, name, &ComponentClass::declare,
          [](Context& context) -> std::unique_ptr<Component> {
            return std::make_unique<ComponentClass>(context);
          }};
}

}  // namespace mocap

// Makes the enclosing shared library a plugin named `plugin_name` (the launch files'
// `plugin:` value). One component per library.
#define MOCAP_REGISTER_COMPONENT(ComponentClass, plugin_name)                        \
  extern "C" __attribute__((visibility("default"))) const ::mocap::ComponentFactory* \
  mocap_component_factory() {                                                        \
    static constexpr ::mocap::ComponentFactory factory =                             \
        ::mocap::make_component_factory<ComponentClass>(plugin_name);                \
    return &factory;                                                                 \
  }
