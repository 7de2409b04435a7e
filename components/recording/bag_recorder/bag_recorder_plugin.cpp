// bag_recorder: records topics of the deployment into a rosbag2 bag (MCAP or sqlite3) from
// inside a launch file. Messages of this process arrive by pointer and are serialized only by
// the writer thread; the others arrive over DDS. Storage and crash safety: mocap/bag/recorder.hpp.
#include <chrono>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <mocap/bag/bag_error.hpp>
#include <mocap/bag/recorder.hpp>
#include <mocap/component.hpp>
#include <mocap/forced_exit_hook.hpp>

namespace mocap::bag {
namespace {

int64_t stamp_ns(Clock::time_point time) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(time.time_since_epoch()).count();
}

struct Settings {
  std::string output;               // empty: bag_YYYY_MM_DD-HH_MM_SS
  std::vector<std::string> topics;  // empty: every topic a component publishes
  // Not BagWriterOptions' sqlite3 (what the library writes when asked nothing): a recording
  // made from a launch file is a new one, and ROS 2 has written MCAP by default since Iron.
  std::string storage = "mcap";
  int64_t commit_interval_ms = 100;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("output", "the bag directory to create (empty: bag_YYYY_MM_DD-HH_MM_SS)",
             &Settings::output)
        .path()
        .add("topics",
             "topics to record (empty: every topic a component of the launch file publishes)",
             &Settings::topics)
        .add("storage",
             "mcap (one .mcap file, zstd-compressed chunks; ROS 2's default since Iron) "
             "or sqlite3 (a .db3 database, ROS 2 Humble's default)",
             &Settings::storage)
        .add("commit_interval_ms",
             "the most a kill can lose: messages are committed at least this often",
             &Settings::commit_interval_ms)
        .range(1, 60000);

class BagRecorder final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Records topics of the deployment into a rosbag2 bag (MCAP or sqlite3), each message "
        "stamped with its receive time. Topics are those the launch file's components declare; "
        "messages of this process are serialized only when written.");
    kParameters.declare(spec);
    spec.subscribes_any("the recorded topics, with their declared types");
  }

  explicit BagRecorder(Context& context) : Component(context) {
    std::string output = settings_.output;
    if (output.empty()) output = default_bag_directory();
    const std::vector<std::string> wanted = settings_.topics;
    const std::vector<KnownTopic> known = context.known_topics();

    std::vector<const KnownTopic*> recorded;
    for (const std::string& name : wanted) {
      const KnownTopic* found = nullptr;
      for (const KnownTopic& topic : known) {
        if (topic.topic == name) found = &topic;
      }
      if (found == nullptr) {
        std::vector<std::string> names;
        for (const KnownTopic& topic : known) names.push_back(topic.topic);
        throw std::invalid_argument(fmt::format(
            "topics: '{}' is not a topic any component of the launch file declares (known: {})",
            name, fmt::join(names, ", ")));
      }
      recorded.push_back(found);
    }
    if (wanted.empty()) {
      for (const KnownTopic& topic : known) {
        if (!topic.publishers.empty() && topic.topic.find('{') == std::string::npos) {
          recorded.push_back(&topic);
        }
      }
    }

    RecorderOptions options;
    options.writer.storage = settings_.storage;
    if (options.writer.storage != "mcap" && options.writer.storage != "sqlite3") {
      throw std::invalid_argument(
          fmt::format("storage: '{}' is not mcap or sqlite3", options.writer.storage));
    }
    options.writer.commit_interval = std::chrono::milliseconds(settings_.commit_interval_ms);
    recorder_ = std::make_unique<Recorder>(output, options);
    // A forced exit destroys nothing: metadata.yaml is written from what is committed.
    metadata_first_.emplace([recorder = recorder_.get()] {
      try {
        recorder->write_committed_metadata();
      } catch (const BagError& e) {
        fmt::print(stderr, "bag_recorder: {}\n", e.what());
      }
    });
    for (const KnownTopic* topic : recorded) {
      const MessageType* type = topic->type;
      const uint32_t id =
          recorder_->add_topic({topic->topic, type->name(), "cdr", topic->publishers, 0});
      // Reliable or transient local only where every publisher offers it, so that all match.
      Qos qos = playback_qos(topic->publishers);
      qos.history = History::KeepAll;
      qos.depth = 1000;
      context.subscribe_any(topic->topic, *type, qos,
                            [this, id, type](const std::shared_ptr<const void>& message) {
                              recorder_->record(id, stamp_ns(now()), message, type);
                              report_error();
                            });
    }
    log().info("recording {} topic(s) to {}", recorded.size(), recorder_->directory());
  }

  ~BagRecorder() override {
    const auto error = recorder_->close();
    const RecorderStats stats = recorder_->stats();
    log().info("recorded {} message(s), {:.1f} MB, to {}{}", stats.written,
               static_cast<double>(stats.bytes) / 1e6, recorder_->directory(),
               stats.dropped ? fmt::format("; {} dropped", stats.dropped) : "");
    if (error && !reported_) log().error("{}", *error);
  }

 private:
  // A full disk ends the recording, not the deployment: said once, then counted as drops.
  void report_error() {
    if (reported_) return;
    if (auto error = recorder_->error()) {
      reported_ = true;
      log().error("recording stopped: {}", *error);
    }
  }

  std::unique_ptr<Recorder> recorder_;
  std::optional<ForcedExitHook> metadata_first_;  // gone before the recorder
  bool reported_ = false;
};

}  // namespace
}  // namespace mocap::bag

MOCAP_REGISTER_COMPONENT(mocap::bag::BagRecorder, "bag_recorder")
