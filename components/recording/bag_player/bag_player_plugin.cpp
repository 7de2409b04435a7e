// bag_player: plays a bag into a deployment, in place of the sensors that made it (a camera,
// the PixArt bridge). Each topic is published with its recorded type, deserialized, so that
// components of this process receive it by pointer, and with the QoS its recorded publishers
// offered (a launch file's qos: overrides it). Pacing: mocap/bag/playback.hpp.
#include <algorithm>
#include <atomic>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <mocap/bag/bag_reader.hpp>
#include <mocap/bag/playback.hpp>
#include <mocap/component.hpp>
#include <mocap/raw_message_type.hpp>

namespace mocap::bag {
namespace {

// Playback's options with what only the plugin reads.
struct Settings : PlaybackOptions {
  std::string bag;
  double start_delay_s = 0.5;
  double exit_after_s = -1;  // negative: run on
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("bag", "the bag directory, or one .mcap or .db3 file", &Settings::bag)
        .path()
        .add("rate", "pace relative to the recording; 0: as fast as possible", &Settings::rate)
        .min(0)
        .add("loop", "start again after the last message", &Settings::loop)
        .add("topics", "topics to play (empty: all)", &Settings::topics)
        .add("start_delay_s",
             "seconds to wait before the first message, for subscribers in other processes to "
             "be discovered",
             &Settings::start_delay_s)
        .range(0, 3600)
        .add("exit_after_s",
             "offline runs: end the process (exit status 0) this many seconds after the last "
             "message, the time the graph needs to finish with it; negative: run on",
             &Settings::exit_after_s)
        .range(-1, 3600);

class BagPlayer final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Plays a rosbag2 bag (MCAP or sqlite3) into the deployment at its recorded pace times "
        "`rate` "
        "(0: as fast as subscribers take them, in order; reliable subscribers are never "
        "overrun). Message stamps are the recorded ones.");
    kParameters.declare(spec);
    spec.publishes_any("the bag's topics, with their recorded types");
  }

  explicit BagPlayer(Context& context) : Component(context) {
    const std::string path = settings_.bag;
    if (path.empty())
      throw std::invalid_argument("bag: give the bag directory, or one .mcap or .db3 file");
    reader_ = std::make_unique<BagReader>(path);
    for (const std::string& problem : reader_->problems()) log().warn("{}", problem);

    for (const BagTopic& topic : reader_->metadata().topics) {
      if (!settings_.topics.empty() && std::find(settings_.topics.begin(), settings_.topics.end(),
                                                 topic.name) == settings_.topics.end()) {
        continue;
      }
      if (topic.type.empty()) {
        log().warn("{}: not played: its type is unknown (no schema names it)", topic.name);
        continue;
      }
      const MessageType* type = find_message_type(topic.type);
      if (type == nullptr) {
        // Not built into this process: passed on as bytes, which only other processes read.
        raw_types_.push_back(std::make_unique<RawMessageType>(dds_type_name(topic.type)));
        type = raw_types_.back().get();
        log().info("{}: type {} is not built in; played to other processes only", topic.name,
                   topic.type);
      }
      // Keep all: at rate 0 a reliable subscriber holds the player back rather than miss
      // messages.
      Qos qos = playback_qos(topic.offered_qos);
      qos.history = History::KeepAll;
      qos.depth = 1000;
      topics_[topic.name] = {type, context.advertise_any(topic.name, *type, qos)};
    }
    // Workers start once the process runs, when every component of it subscribes; playback
    // waits start_delay_s more for the subscribers of other processes.
    create_worker("playback", [this](std::stop_token stop) {
      const auto delay = std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::duration<double>(settings_.start_delay_s));
      if (!wait_for_stop(stop, delay)) return;
      std::atomic<bool> stopped{false};  // what the bag library's play() watches
      const std::stop_callback on_stop(stop, [&stopped] { stopped.store(true); });
      run(stopped);
      if (!stopped.load()) exit_later(stop);
    });
  }

 private:
  struct Topic {
    const MessageType* type = nullptr;
    std::shared_ptr<PublisherPort> publisher;
  };

  void run(const std::atomic<bool>& stop) {
    uint64_t dropped = 0;
    const PlaybackStats stats = play(
        *reader_, settings_,
        [&](const BagMessage& message) {
          auto topic = topics_.find(message.topic->name);
          if (topic == topics_.end()) return;
          const MessageType& type = *topic->second.type;
          std::shared_ptr<void> typed = type.create();
          try {
            type.deserialize(message.data, typed.get());
          } catch (const SerializationError& e) {
            if (dropped++ == 0)
              log().warn("{}: a message does not deserialize: {}", message.topic->name, e.what());
            return;
          }
          topic->second.publisher->publish(std::move(typed));
        },
        stop);
    log().info("played {} message(s){}", stats.published,
               dropped ? fmt::format(", {} dropped (not deserializable)", dropped) : "");
  }

  // exit_after_s after the last message, the process ends (an offline run).
  void exit_later(const std::stop_token& stop) {
    if (settings_.exit_after_s < 0 || settings_.loop) return;
    const auto after = std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double>(settings_.exit_after_s));
    if (wait_for_stop(stop, after)) request_shutdown(0);
  }

  std::unique_ptr<BagReader> reader_;
  std::vector<std::unique_ptr<RawMessageType>> raw_types_;
  std::map<std::string, Topic> topics_;
};

}  // namespace
}  // namespace mocap::bag

MOCAP_REGISTER_COMPONENT(mocap::bag::BagPlayer, "bag_player")
