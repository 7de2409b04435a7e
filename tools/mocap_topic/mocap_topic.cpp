// mocap_topic: what is on the DDS domain, and what goes over it.
#include <array>
#include <charconv>
#include <condition_variable>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include <mocap/generated_message_types.hpp>
#include <mocap/message_time.hpp>
#include <motion_capture_tracking_interfaces/msg/named_pose_array.hpp>

#include <mocap/raw_message_type.hpp>
#include "core/rate_estimator.hpp"
#include "core/shutdown_signal.hpp"
#include "dds/dds_transport.hpp"
#include "host/dds_implementations.hpp"
#include "host/plugin_loader.hpp"
#include "messages/cdr_format.hpp"
#include "messages/idl_schema.hpp"
#include "mocap_topic/doctor_run.hpp"

namespace {

constexpr const char* kUsage = R"(usage:
  mocap_topic list [--wait SECONDS]
  mocap_topic echo TOPIC [--count N] [--full] [--idl FILE]...
  mocap_topic hz TOPIC [--window N] [--count N]
  mocap_topic reseed ROBOT X Y Z [--topic TOPIC] [--wait SECONDS]
  mocap_topic doctor [LAUNCH_FILE] [--seconds S] [--domains LIST]
                     [--security DIR --identity NAME]
options for all: --domain ID (default: MOCAP_DOMAIN_ID, else the launch file's, else 0)

  list   topics seen on the domain, with their types and endpoint counts, and each
         publisher/subscriber pair that cannot connect (QoS or type) and why
  echo   print each message (YAML-like); --count stops after N, --full prints whole arrays,
         --idl adds definitions for types this build does not know
  hz     publication rate from the publisher's timestamps, every second; --window sets the
         samples averaged (default 10000), --count stops after N reports
  reseed tell the volume a swarm robot was carried to (X, Y, Z) (world frame, metres): it is
         looked for there; published on /mocap/reseed (--topic) once the fusion listens,
         waiting up to --wait seconds (default 5)
  doctor why you see nothing: listens for S seconds (default 4) and prints one line per
         finding, each problem with what to do: the processes up and their hosts; participants
         on other domains (it listens to the discovery traffic of domains 0 to 9 and the
         graph's; --domains 0-20,42 for others; a Cyclone DDS participant announces itself
         every 30 s once started, Fast DDS every 3 s); participants that use DDS Security
         (--security and --identity: credentials from scripts/make_security.sh, to see their
         topics; authenticating with each takes a second or more: give it --seconds 10); publishers and subscribers that cannot connect (type, QoS); each process's
         clock against this host's; every /diagnostics status that is not OK, and processes
         whose diagnostics stopped. With LAUNCH_FILE, also its groups that do not run and its
         topics without a writer or a reader. ("all well" when nothing is wrong; mocap-graph
         uses no DDS partitions.) Exit code: 0 all well, 1 problems found, 2 it cannot run.
)";

[[noreturn]] void usage_error(std::string_view message) {
  fmt::print(stderr, "mocap_topic: {}\n\n{}", message, kUsage);
  std::exit(2);
}

size_t parse_number(std::string_view option, const std::string& text, size_t min, size_t max) {
  size_t value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value < min || value > max) {
    usage_error(fmt::format("{} {}: expected an integer in [{}, {}]", option, text, min, max));
  }
  return value;
}

void sleep_unless_stopped(std::chrono::milliseconds duration) {
  mocap::ShutdownSignal::wait(duration);
}

// Topics with their types and endpoint counts, and under each topic every publisher and
// subscriber pair that DDS will not connect (QoS or type), whichever implementation each
// runs on: such a subscriber gets nothing, and its own process only logs it.
int list(mocap::DdsTransport& transport, double wait_seconds) {
  sleep_unless_stopped(std::chrono::milliseconds(static_cast<int>(wait_seconds * 1000)));
  struct Topic {
    std::set<std::string> types;
    std::vector<mocap::DiscoveredEndpoint> publishers, subscribers;
  };
  std::map<std::string, Topic> topics;
  for (auto& endpoint : transport.discovered_endpoints()) {
    Topic& topic = topics[endpoint.topic];
    topic.types.insert(mocap::ros_type_name(endpoint.type));
    (endpoint.is_publisher ? topic.publishers : topic.subscribers).push_back(std::move(endpoint));
  }
  for (const auto& [name, topic] : topics) {
    std::vector<std::string> mismatches;
    for (const auto& subscriber : topic.subscribers) {
      for (const auto& publisher : topic.publishers) {
        auto why = publisher.type != subscriber.type
                       ? std::optional<std::string>(fmt::format(
                             "types differ ({} vs {})", mocap::ros_type_name(publisher.type),
                             mocap::ros_type_name(subscriber.type)))
                       : mocap::qos_mismatch(publisher.qos, subscriber.qos);
        if (why) {
          mismatches.push_back(
              fmt::format("  incompatible: publisher of '{}' -> subscriber of "
                          "'{}': {}",
                          publisher.participant, subscriber.participant, *why));
        }
      }
    }
    fmt::print(
        "{} [{}] {} publisher(s), {} subscriber(s){}\n", name, fmt::join(topic.types, ", "),
        topic.publishers.size(), topic.subscribers.size(),
        mismatches.empty() ? "" : fmt::format(", {} incompatible pair(s)", mismatches.size()));
    for (const auto& line : mismatches) fmt::print("{}\n", line);
  }
  return 0;
}

// Waits for the topic's publishers; returns their type and a QoS every one of them matches.
std::optional<std::pair<std::string, mocap::Qos>> find_publishers(mocap::DdsTransport& transport,
                                                                  const std::string& topic) {
  auto start = std::chrono::steady_clock::now();
  bool announced = false;
  while (!mocap::ShutdownSignal::received()) {
    std::set<std::string> types;
    mocap::Qos qos{mocap::Reliability::Reliable, mocap::Durability::TransientLocal,
                   mocap::History::KeepLast, 1000};
    for (const auto& endpoint : transport.discovered_endpoints()) {
      if (endpoint.topic != topic || !endpoint.is_publisher) continue;
      types.insert(endpoint.type);
      if (endpoint.qos.reliability == mocap::Reliability::BestEffort) {
        qos.reliability = mocap::Reliability::BestEffort;
      }
      if (endpoint.qos.durability == mocap::Durability::Volatile) {
        qos.durability = mocap::Durability::Volatile;
      }
    }
    if (types.size() > 1) {
      fmt::print(stderr, "mocap_topic: {} is published with several types: {}\n", topic,
                 fmt::join(types, ", "));
      return std::nullopt;
    }
    if (types.size() == 1) return std::make_pair(*types.begin(), qos);
    if (!announced && std::chrono::steady_clock::now() - start > std::chrono::seconds(1)) {
      fmt::print(stderr, "waiting for a publisher of {} ...\n", topic);
      announced = true;
    }
    sleep_unless_stopped(std::chrono::milliseconds(50));
  }
  return std::nullopt;
}

// Calls `each` for every message received, from this thread, until it returns false.
template <class Each>
int receive(mocap::DdsTransport& transport, const std::string& topic,
            const mocap::RawMessageType& type, const mocap::Qos& qos, Each each) {
  std::mutex mutex;
  std::condition_variable arrived;
  bool pending = false;
  auto subscription = transport.subscribe({topic, &type, qos, "mocap_topic"}, [&](bool) {
    std::lock_guard lock(mutex);
    pending = true;
    arrived.notify_one();
  });
  mocap::ReceivedMessage received;
  while (!mocap::ShutdownSignal::received()) {
    while (subscription->take(received)) {
      if (!each(received)) return 0;
    }
    std::unique_lock lock(mutex);
    arrived.wait_for(lock, std::chrono::milliseconds(100), [&] { return pending; });
    pending = false;
  }
  return 0;
}

int echo(mocap::DdsTransport& transport, const std::string& topic, size_t count, bool full,
         const std::vector<std::string>& idl_files) {
  auto found = find_publishers(transport, topic);
  if (!found) return 1;
  auto [dds_type, qos] = *found;
  mocap::IdlSchema schema;
  try {
    for (const std::string& file : idl_files) {
      std::ifstream stream(file);
      if (!stream) {
        fmt::print(stderr, "mocap_topic: cannot read {}\n", file);
        return 1;
      }
      std::stringstream text;
      text << stream.rdbuf();
      schema.parse(text.str());
    }
    if (const mocap::MessageType* known = mocap::find_message_type(dds_type)) {
      schema.parse(mocap::full_definition(*known));
    }
  } catch (const mocap::IdlError& e) {
    fmt::print(stderr, "mocap_topic: {}\n", e.what());
    return 1;
  }
  mocap::RawMessageType type(dds_type);
  if (schema.find(type.name()) == nullptr) {
    fmt::print(stderr,
               "mocap_topic: {} has type {}, which this build does not know; pass its IDL "
               "with --idl FILE\n",
               topic, type.name());
    return 1;
  }
  mocap::CdrFormatOptions options;
  if (full) options.max_items = SIZE_MAX;
  size_t printed = 0;
  return receive(transport, topic, type, qos, [&](const mocap::ReceivedMessage& received) {
    const auto& bytes = *static_cast<const std::vector<uint8_t>*>(received.message.get());
    try {
      fmt::print("{}---\n", mocap::format_cdr(schema, type.name(), bytes, options));
    } catch (const std::exception& e) {
      fmt::print("# cannot show this message: {}\n---\n", e.what());
    }
    std::fflush(stdout);
    return ++printed < count;
  });
}

int hz(mocap::DdsTransport& transport, const std::string& topic, size_t window, size_t count) {
  auto found = find_publishers(transport, topic);
  if (!found) return 1;
  auto [dds_type, qos] = *found;
  mocap::RawMessageType type(dds_type);
  mocap::RateEstimator estimator(window);
  size_t reports = 0;
  auto next_report = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  return receive(transport, topic, type, qos, [&](const mocap::ReceivedMessage& received) {
    estimator.add(received.source_time);
    if (std::chrono::steady_clock::now() < next_report) return true;
    next_report += std::chrono::seconds(1);
    if (auto stats = estimator.stats()) {
      fmt::print(
          "average rate: {:.3f} Hz\n  min: {:.6f} s  max: {:.6f} s  std dev: {:.6f} s  "
          "window: {}\n",
          stats->rate_hz, stats->min_period_s, stats->max_period_s, stats->stddev_period_s,
          stats->samples);
      std::fflush(stdout);
      return ++reports < count;
    }
    return true;
  });
}

double parse_coordinate(const std::string& text) {
  double value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) {
    usage_error(fmt::format("{}: expected a number of metres", text));
  }
  return value;
}

// One re-seed for the fusion, published once a subscriber listens: the fusion takes robots'
// new positions on a reliable topic.
int reseed(mocap::DdsTransport& transport, const std::string& topic, const std::string& robot,
           const std::array<double, 3>& position, double wait_seconds) {
  using motion_capture_tracking_interfaces::msg::NamedPoseArray;
  const mocap::Endpoint endpoint{topic, &mocap::message_type<NamedPoseArray>(),
                                 mocap::Qos::reliable(), "mocap_topic"};
  auto publisher = transport.advertise(endpoint);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_seconds);
  while (publisher->matched_subscribers() == 0 && std::chrono::steady_clock::now() < deadline &&
         !mocap::ShutdownSignal::received()) {
    sleep_unless_stopped(std::chrono::milliseconds(50));
  }
  if (publisher->matched_subscribers() == 0) {
    fmt::print(stderr,
               "mocap_topic: nothing subscribes to {} within {} s: is volume_fusion running with "
               "a robots file, on this domain?\n",
               topic, wait_seconds);
    return 1;
  }
  auto message = std::make_shared<NamedPoseArray>();
  message->header().stamp(mocap::to_time_msg(mocap::Clock::now()));
  message->header().frame_id("world");
  motion_capture_tracking_interfaces::msg::NamedPose named;
  named.name(robot);
  named.pose().position().x(position[0]);
  named.pose().position().y(position[1]);
  named.pose().position().z(position[2]);
  named.pose().orientation().w(1);
  message->poses().push_back(named);
  publisher->publish(message, mocap::Clock::now());
  // Reliable delivery takes a moment after the call; the process must not leave before.
  sleep_unless_stopped(std::chrono::milliseconds(500));
  fmt::print("{}: looked for at ({}, {}, {}) (on {})\n", robot, position[0], position[1],
             position[2], topic);
  return 0;
}

}  // namespace

// "0-9,42" -> 0..9 and 42.
std::vector<int> parse_domains(const std::string& text) {
  std::vector<int> domains;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    const size_t dash = item.find('-');
    const size_t first = parse_number("--domains", item.substr(0, dash), 0, 232);
    const size_t last = dash == std::string::npos
                            ? first
                            : parse_number("--domains", item.substr(dash + 1), first, 232);
    for (size_t d = first; d <= last; ++d) domains.push_back(static_cast<int>(d));
    start = comma + 1;
  }
  return domains;
}

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) usage_error("no command given");
  if (args[0] == "--help" || args[0] == "-h") {
    fmt::print("{}", kUsage);
    return 0;
  }
  std::string command = args[0];
  std::optional<std::string> topic;
  std::vector<std::string> positional;
  std::optional<int> domain;
  size_t count = SIZE_MAX, window = 10000;
  std::optional<double> wait_seconds;  // list: 1.5, reseed: 5
  bool full = false;
  std::vector<std::string> idl_files;
  mocap::doctor::DoctorCommand doctor;
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) usage_error(fmt::format("{} needs a value", arg));
      return args[++i];
    };
    if (arg == "--domain") {
      domain = static_cast<int>(parse_number(arg, value(), 0, 232));
    } else if (arg == "--count") {
      count = parse_number(arg, value(), 1, SIZE_MAX);
    } else if (arg == "--window") {
      window = parse_number(arg, value(), 2, 10000000);
    } else if (arg == "--wait") {
      wait_seconds = std::atof(value().c_str());
    } else if (arg == "--topic" && command == "reseed") {
      topic = value();
    } else if (arg == "--seconds" && command == "doctor") {
      doctor.seconds = static_cast<double>(parse_number(arg, value(), 1, 600));
    } else if (arg == "--domains" && command == "doctor") {
      doctor.domains = parse_domains(value());
    } else if (arg == "--security" && command == "doctor") {
      doctor.security_directory = value();
    } else if (arg == "--identity" && command == "doctor") {
      doctor.security_identity = value();
    } else if (arg == "--full") {
      full = true;
    } else if (arg == "--idl") {
      idl_files.push_back(value());
    } else if (arg.starts_with("-") && !(command == "reseed" && positional.size() >= 1)) {
      usage_error(fmt::format("unknown option {}", arg));
    } else if (command == "reseed") {
      positional.push_back(arg);
    } else if (!topic) {
      topic = arg;
    } else {
      usage_error(fmt::format("unexpected argument {}", arg));
    }
  }
  std::array<double, 3> position{};
  if (command == "reseed") {
    if (positional.size() != 4) usage_error("reseed needs ROBOT X Y Z");
    for (int i = 0; i < 3; ++i) position[i] = parse_coordinate(positional[i + 1]);
    if (!topic) topic = "/mocap/reseed";
  }
  if (command != "list" && command != "doctor" && !topic) {
    usage_error(fmt::format("{} needs a TOPIC", command));
  }
  if (doctor.security_directory.empty() != doctor.security_identity.empty()) {
    usage_error("--security and --identity go together");
  }
  if (domain) setenv("MOCAP_DOMAIN_ID", std::to_string(*domain).c_str(), 1);

  mocap::ShutdownSignal::install();
  mocap::generated_message_types();  // registers the known types for echo
  for (const std::string& error : mocap::PluginLoader().load_message_libraries()) {
    fmt::print(stderr, "mocap_topic: {}\n", error);  // its types stay unknown: echo says so
  }
  if (command == "doctor") {
    doctor.launch_file = topic;
    return mocap::doctor::run_doctor(doctor);
  }
  try {
    auto dds = mocap::make_dds_transport(mocap::DdsOptions{}, "mocap_topic");
    mocap::DdsTransport& transport = *dds;
    if (command == "list") return list(transport, wait_seconds.value_or(1.5));
    if (command == "echo") return echo(transport, *topic, count, full, idl_files);
    if (command == "hz") return hz(transport, *topic, window, count);
    if (command == "reseed") {
      return reseed(transport, *topic, positional[0], position, wait_seconds.value_or(5));
    }
  } catch (const std::exception& e) {
    fmt::print(stderr, "mocap_topic: {}\n", e.what());
    return 1;
  }
  usage_error(fmt::format("unknown command {}", command));
}
