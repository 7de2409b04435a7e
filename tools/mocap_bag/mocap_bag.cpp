// mocap_bag: record DDS topics into a bag, play a bag back onto DDS, describe a bag. Bags are
// rosbag2 sqlite3 bags (ROS 2 Humble's layout): `ros2 bag` reads ours and we read theirs.
#include <charconv>
#include <condition_variable>
#include <cstdlib>
#include <ctime>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <mocap/bag/bag_reader.hpp>
#include <mocap/bag/playback.hpp>
#include <mocap/bag/recorder.hpp>
#include <mocap/generated_message_types.hpp>
#include <mocap/raw_message_type.hpp>

#include "core/shutdown_signal.hpp"
#include "dds/dds_transport.hpp"
#include "host/dds_implementations.hpp"
#include "host/plugin_loader.hpp"
#include "mocap_bag/bag_export.hpp"

namespace {

using mocap::bag::BagError;

constexpr const char* kUsage = R"(usage:
  mocap_bag record [-o DIR] TOPIC... | --all   [--duration SECONDS] [--storage mcap|sqlite3]
  mocap_bag play DIR [--rate R] [--loop] [--topics TOPIC...] [--delay SECONDS]
  mocap_bag info DIR
  mocap_bag export DIR --format c3d|trc|csv|tum [-o PATH] [--bodies BODY...]
                   [--markers [--bodies-file FILE] [--robots-file FILE]]

  record  subscribes to the topics (or to every topic published, as publishers appear) and
          writes what arrives to a new bag directory DIR (default bag_YYYY_MM_DD-HH_MM_SS),
          stamped with its receive time, until Ctrl-C or --duration; --storage: one .mcap
          file, zstd-compressed chunks (the default, as ROS 2 since Iron) or a .db3 database
          (ROS 2 Humble's default); play and info read both
  play    publishes a bag's messages with their recorded types and QoS, at their recorded
          pace times R (default 1; 0: as fast as possible, in order), after waiting --delay
          seconds (default 1) for subscribers to be discovered
  info    what a bag holds: files, duration, topics with types and counts, and what is damaged
  export  the bodies of /mocap/poses, at the bag's rate, in a format analysis tools read:
          c3d (Z up, mm; each body as four points: its origin and axis ends 0.1 m out), trc
          (OpenSim's, Y up, m; bodies as in c3d), csv (Motive's CSV export: rigid bodies'
          quaternion and position, Y up, m) or tum (evo's and the TUM benchmark's "timestamp
          tx ty tz qx qy qz qw", world frame; PATH a folder, one <body>.tum per body, default
          DIR_tum); PATH the file, default DIR.c3d, DIR.trc, DIR.csv. --bodies: only these.
          --markers: /mocap/markers too, a labeled marker as <body>_<n>, the others as
          unlabeled_<track>; its body named from the fusion's --bodies-file and --robots-file
          (a cloud gives the index in their list)

options for record and play: --domain ID (default: MOCAP_DOMAIN_ID, else 0)
exit status: 0 done, 1 the bag cannot be written or read, 2 bad arguments
)";

[[noreturn]] void usage_error(const std::string& message) {
  fmt::print(stderr, "mocap_bag: {}\n\n{}", message, kUsage);
  std::exit(2);
}

double parse_seconds(const std::string& option, const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !(value >= 0)) {
    usage_error(fmt::format("{} {}: expected a number of at least 0", option, text));
  }
  return value;
}

int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             mocap::Clock::now().time_since_epoch())
      .count();
}

std::string format_stamp(int64_t ns) {
  const std::time_t seconds = static_cast<std::time_t>(ns / 1000000000);
  std::tm local{};
  localtime_r(&seconds, &local);
  char text[64];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S", &local);
  return fmt::format("{}.{:09} ({}.{:09})", text, ns % 1000000000, ns / 1000000000,
                     ns % 1000000000);
}

// ---- record --------------------------------------------------------------------------

struct RecordedTopic {
  std::unique_ptr<mocap::RawMessageType> type;
  std::unique_ptr<mocap::TransportSubscription> subscription;
  uint32_t id = 0;
};

// Kept whole (about 90 lines): subscribing, the loop and the summary share the subscriptions
// and the writer, and read as one story.
int record(const std::string& directory, const std::set<std::string>& wanted, bool all,
           std::optional<double> duration, const std::string& storage) {
  auto dds = mocap::make_dds_transport(mocap::DdsOptions{}, "mocap_bag");
  mocap::DdsTransport& transport = *dds;
  mocap::bag::RecorderOptions options;
  options.writer.storage = storage;
  mocap::bag::Recorder recorder(directory, options);
  // A second stop request well after the first (the graceful stop hangs) still leaves
  // metadata.yaml agreeing with what the database holds.
  mocap::ForcedExitHook metadata_first([&recorder] {
    try {
      recorder.write_committed_metadata();
    } catch (const mocap::bag::BagError& e) {
      fmt::print(stderr, "mocap_bag: {}\n", e.what());
    }
  });
  fmt::print("recording to {}\n", recorder.directory());
  std::fflush(stdout);

  std::mutex mutex;
  std::condition_variable arrived;
  bool pending = false;
  std::map<std::string, RecordedTopic> topics;
  std::set<std::string> refused;  // topics published with several types: said once
  const auto start = std::chrono::steady_clock::now();
  auto next_discovery = start;

  while (!mocap::ShutdownSignal::received()) {
    const auto now = std::chrono::steady_clock::now();
    if (duration && now - start >= std::chrono::duration<double>(*duration)) break;
    if (now >= next_discovery) {
      next_discovery = now + std::chrono::milliseconds(100);
      // Publishers seen so far, by topic: their types and offered QoS.
      std::map<std::string, std::pair<std::set<std::string>, std::vector<mocap::Qos>>> offers;
      for (const auto& endpoint : transport.discovered_endpoints()) {
        if (!endpoint.is_publisher || topics.count(endpoint.topic) != 0) continue;
        if (!all && wanted.count(endpoint.topic) == 0) continue;
        auto& [types, qos] = offers[endpoint.topic];
        types.insert(endpoint.type);
        qos.push_back(endpoint.qos);
      }
      for (auto& [name, offer] : offers) {
        const auto& [types, offered] = offer;
        if (types.size() > 1) {
          if (refused.insert(name).second) {
            fmt::print(stderr,
                       "mocap_bag: not recording {}: it is published with several types ({})\n",
                       name, fmt::join(types, ", "));
          }
          continue;
        }
        RecordedTopic& topic = topics[name];
        topic.type = std::make_unique<mocap::RawMessageType>(*types.begin());
        topic.id = recorder.add_topic({name, topic.type->name(), "cdr", offered, 0});
        // What every publisher can match: reliable or transient local only if all are.
        mocap::Qos requested = mocap::bag::playback_qos(offered);
        requested.history = mocap::History::KeepAll;
        requested.depth = 1000;
        topic.subscription =
            transport.subscribe({name, topic.type.get(), requested, "mocap_bag"}, [&](bool) {
              std::lock_guard lock(mutex);
              pending = true;
              arrived.notify_one();
            });
        fmt::print("subscribed to {} [{}]\n", name, topic.type->name());
        std::fflush(stdout);
      }
    }
    mocap::ReceivedMessage received;
    for (auto& [name, topic] : topics) {
      while (topic.subscription->take(received)) {
        recorder.record(topic.id, now_ns(), received.message, nullptr);
      }
    }
    if (auto error = recorder.error()) break;
    std::unique_lock lock(mutex);
    arrived.wait_for(lock, std::chrono::milliseconds(20), [&] { return pending; });
    pending = false;
  }
  for (auto& [name, topic] : topics) topic.subscription.reset();
  const auto error = recorder.close();
  const mocap::bag::RecorderStats stats = recorder.stats();
  fmt::print("recorded {} message(s) on {} topic(s), {:.1f} MB, to {}{}\n", stats.written,
             topics.size(), static_cast<double>(stats.bytes) / 1e6, recorder.directory(),
             stats.dropped ? fmt::format("; {} dropped", stats.dropped) : "");
  if (error) {
    fmt::print(stderr, "mocap_bag: {}\n", *error);
    return 1;
  }
  return 0;
}

// ---- play ----------------------------------------------------------------------------

int play(const std::string& path, const mocap::bag::PlaybackOptions& options, double delay) {
  mocap::bag::BagReader reader(path);
  for (const std::string& problem : reader.problems()) {
    fmt::print(stderr, "mocap_bag: {}\n", problem);
  }
  auto dds = mocap::make_dds_transport(mocap::DdsOptions{}, "mocap_bag");
  mocap::DdsTransport& transport = *dds;
  std::vector<std::unique_ptr<mocap::RawMessageType>> types;
  std::map<std::string, std::unique_ptr<mocap::TransportPublisher>> publishers;
  const std::set<std::string> only(options.topics.begin(), options.topics.end());
  for (const mocap::bag::BagTopic& topic : reader.metadata().topics) {
    if (!only.empty() && only.count(topic.name) == 0) continue;
    if (topic.serialization_format != "cdr") {
      fmt::print(stderr, "mocap_bag: not playing {}: serialization format '{}' (only cdr)\n",
                 topic.name, topic.serialization_format);
      continue;
    }
    if (topic.type.empty()) {
      fmt::print(stderr, "mocap_bag: not playing {}: its type is unknown (no schema names it)\n",
                 topic.name);
      continue;
    }
    types.push_back(std::make_unique<mocap::RawMessageType>(mocap::dds_type_name(topic.type)));
    // Keep all: at rate 0 a reliable subscriber holds the player back rather than miss
    // messages.
    mocap::Qos qos = mocap::bag::playback_qos(topic.offered_qos);
    qos.history = mocap::History::KeepAll;
    qos.depth = 1000;
    publishers[topic.name] =
        transport.advertise({topic.name, types.back().get(), qos, "mocap_bag"});
  }
  for (const std::string& name : only) {
    if (publishers.count(name) == 0) fmt::print(stderr, "mocap_bag: {} is not in the bag\n", name);
  }

  std::atomic<bool> stop{false};
  std::thread watcher([&] {
    while (!stop.load() && !mocap::ShutdownSignal::wait(std::chrono::milliseconds(100))) {
    }
    stop.store(true);
    transport.stop_waiting();  // a publish waiting for a slow subscriber gives up too
  });
  // Subscribers must be discovered first, or the first messages go to nobody.
  mocap::ShutdownSignal::wait(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(delay)));
  mocap::bag::PlaybackStats stats;
  if (!stop.load()) {
    fmt::print("playing {} at rate {}{}\n", path, options.rate, options.loop ? ", looping" : "");
    std::fflush(stdout);
    stats = mocap::bag::play(
        reader, options,
        [&](const mocap::bag::BagMessage& message) {
          auto publisher = publishers.find(message.topic->name);
          if (publisher == publishers.end()) return;
          publisher->second->publish(std::make_shared<const std::vector<uint8_t>>(message.data),
                                     mocap::Clock::now());
        },
        stop);
  }
  stop.store(true);
  watcher.join();
  fmt::print("played {} message(s)\n", stats.published);
  return 0;
}

// ---- info ----------------------------------------------------------------------------

int info(const std::string& path) {
  mocap::bag::BagReader reader(path);
  const mocap::bag::BagMetadata& metadata = reader.metadata();
  fmt::print("Files:             {}\n", fmt::join(
                                            [&] {
                                              std::vector<std::string> files;
                                              for (const auto& file : metadata.files)
                                                files.push_back(file.path);
                                              return files;
                                            }(),
                                            ", "));
  fmt::print("Storage id:        {}\n", metadata.storage_identifier);
  fmt::print("Duration:          {:.3f} s\n", static_cast<double>(metadata.duration_ns) / 1e9);
  if (metadata.message_count > 0) {
    fmt::print("Start:             {}\n", format_stamp(metadata.start_ns));
    fmt::print("End:               {}\n", format_stamp(metadata.start_ns + metadata.duration_ns));
  }
  fmt::print("Messages:          {}\n", metadata.message_count);
  fmt::print("Topic information:");
  if (metadata.topics.empty()) fmt::print("\n");
  for (size_t i = 0; i < metadata.topics.size(); ++i) {
    const auto& topic = metadata.topics[i];
    fmt::print("{}Topic: {} | Type: {} | Count: {} | Serialization Format: {}\n",
               i == 0 ? " " : "                   ", topic.name, topic.type, topic.message_count,
               topic.serialization_format);
  }
  if (!reader.problems().empty()) {
    fmt::print("Damage:\n");
    for (const std::string& problem : reader.problems()) fmt::print("  {}\n", problem);
  }
  return 0;
}

}  // namespace

// Kept whole (about 85 lines): one option parser for the three commands, whose options
// overlap.
int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) usage_error("no command given");
  if (args[0] == "--help" || args[0] == "-h") {
    fmt::print("{}", kUsage);
    return 0;
  }
  const std::string command = args[0];
  if (command != "record" && command != "play" && command != "info" && command != "export") {
    usage_error(fmt::format("unknown command {}", command));
  }
  std::optional<std::string> output, bag;
  std::set<std::string> topics;
  bool all = false;
  std::string storage = "mcap";
  std::optional<double> duration;
  double delay = 1.0;
  mocap::bag::PlaybackOptions playback;
  bool in_topics = false;  // play's --topics takes the arguments after it
  mocap::bag_export::ExportOptions exporting;
  bool in_bodies = false;  // export's --bodies takes the arguments after it
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) usage_error(fmt::format("{} needs a value", arg));
      return args[++i];
    };
    if (arg.starts_with("-")) in_topics = in_bodies = false;
    if (arg == "-o" || arg == "--output") {
      output = value();
    } else if (arg == "--all") {
      all = true;
    } else if (arg == "--storage") {
      storage = value();
      if (storage != "mcap" && storage != "sqlite3") {
        usage_error(fmt::format("--storage {}: expected mcap or sqlite3", storage));
      }
    } else if (arg == "--duration") {
      duration = parse_seconds(arg, value());
    } else if (arg == "--rate") {
      playback.rate = parse_seconds(arg, value());
    } else if (arg == "--loop") {
      playback.loop = true;
    } else if (arg == "--delay") {
      delay = parse_seconds(arg, value());
    } else if (arg == "--topics") {
      in_topics = true;
    } else if (arg == "--bodies") {
      in_bodies = true;
    } else if (arg == "--format") {
      exporting.format = value();
    } else if (arg == "--markers") {
      exporting.markers = true;
    } else if (arg == "--bodies-file") {
      exporting.bodies_file = value();
    } else if (arg == "--robots-file") {
      exporting.robots_file = value();
    } else if (arg == "--domain") {
      const std::string& text = value();
      int domain = -1;
      auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), domain);
      if (error != std::errc() || end != text.data() + text.size() || domain < 0 || domain > 232) {
        usage_error(fmt::format("--domain {}: expected 0 to 232", text));
      }
      setenv("MOCAP_DOMAIN_ID", text.c_str(), 1);
    } else if (arg.starts_with("-")) {
      usage_error(fmt::format("unknown option {}", arg));
    } else if (command == "record") {
      if (!arg.starts_with("/")) usage_error(fmt::format("{}: topics start with '/'", arg));
      topics.insert(arg);
    } else if (in_topics) {
      playback.topics.push_back(arg);
    } else if (in_bodies) {
      exporting.bodies.push_back(arg);
    } else if (!bag) {
      bag = arg;
    } else {
      usage_error(fmt::format("unexpected argument {}", arg));
    }
  }
  if (command == "record" && all == !topics.empty()) {
    usage_error("record needs TOPIC... or --all (not both)");
  }
  if (command != "record" && !bag) usage_error(fmt::format("{} needs a bag DIR", command));

  mocap::ShutdownSignal::install();
  mocap::generated_message_types();  // the shipped types, and below those of your projects
  for (const std::string& error : mocap::PluginLoader().load_message_libraries()) {
    fmt::print(stderr, "mocap_bag: {}\n", error);
  }
  try {
    if (command == "record")
      return record(output.value_or(mocap::bag::default_bag_directory()), topics, all, duration,
                    storage);
    if (command == "play") return play(*bag, playback, delay);
    if (command == "export") {
      if (exporting.format.empty()) usage_error("export needs --format c3d, trc, csv or tum");
      exporting.output = output;
      return mocap::bag_export::export_bag(*bag, exporting);
    }
    return info(*bag);
  } catch (const std::exception& e) {
    fmt::print(stderr, "mocap_bag: {}\n", e.what());
    return 1;
  }
}
