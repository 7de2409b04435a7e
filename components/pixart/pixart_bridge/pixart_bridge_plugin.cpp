// pixart_bridge: PixArt points from a CAN bus (can_source.hpp, pixart_bridge.hpp), published
// raw and as one FiducialArray per camera sample, so that downstream components treat each
// PixArt sensor like any camera.
#include <chrono>
#include <memory>

#include <mocap/component.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <mocap_msgs/msg/pixart_raw_point_array.hpp>

#include "common/can_io/can_source.hpp"
#include "common/topics/graph_topics.hpp"
#include "pixart/pixart_bridge/camera_samples.hpp"
#include "pixart/pixart_bridge/pixart_bridge.hpp"

namespace mocap::pixart {
namespace {

// Uncertainty of a PixArt coordinate: the sensor reports whole pixels (1/sqrt(12) px).
constexpr float kQuantisationPx = 0.29f;

// The decoder's and each CAN source's options with what only the plugin reads.
struct Settings : PixartDecoderOptions {
  std::string source = "slcan";  // slcan, socketcan or candump
  can::SlcanSourceOptions slcan{.device = "/dev/ttyACM0"};
  std::string interface = "can0";  // socketcan
  can::CandumpSourceOptions candump;
  std::vector<std::string> camera_names;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("source", "slcan, socketcan or candump", &Settings::source)
        .add("device", "slcan: the adaptor's serial device", &Settings::slcan,
             &can::SlcanSourceOptions::device)
        .path()
        .add("bitrate", "slcan: CAN bitrate, bit/s", &Settings::slcan,
             &can::SlcanSourceOptions::bitrate)
        .range(10000, 1000000)
        .add("baud", "slcan: serial baud rate (USB adaptors ignore it)", &Settings::slcan,
             &can::SlcanSourceOptions::baud)
        .range(9600, 3000000)
        .add("interface", "socketcan: the CAN interface", &Settings::interface)
        .add("file", "candump: a `candump -L` log", &Settings::candump,
             &can::CandumpSourceOptions::file)
        .path()
        .add("recorded_timing", "candump: replay at the recorded pace (false: as fast as possible)",
             &Settings::candump, &can::CandumpSourceOptions::recorded_timing)
        .add("base_id", "CAN ID of box 0, camera 0, points 0-1", &Settings::base_id)
        .range(0, 0x7FF)
        .add("boxes", "camera boxes on the bus (4 cameras each)", &Settings::boxes)
        .range(1, 64)
        .add("camera_names", "name of camera 0, 1, ...: topic and frame id; others are camera<N>",
             &Settings::camera_names);

class PixartBridge final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Reads PixArt IR sensors' points from a CAN bus (SLCAN adaptor, SocketCAN or a candump "
        "log), publishes them raw and as one fiducial array per camera sample.");
    kParameters.declare(spec);
    spec.publishes<mocap_msgs::msg::PixartRawPointArray>(
        topics::kPixartRaw, Qos::reliable(), "the points decoded from each batch of frames read");
    spec.publishes<mocap_msgs::msg::FiducialArray>(
        topics::kPixartFiducials, Qos::reliable(),
        "one array per camera sample (up to 4 points, pixels), frame id = camera name");
  }

  explicit PixartBridge(Context& context) : Component(context), decoder_(settings_) {
    if (settings_.source != "slcan" && settings_.source != "socketcan" &&
        settings_.source != "candump") {
      throw std::invalid_argument("parameter 'source' is '" + settings_.source +
                                  "'; expected slcan, socketcan or candump");
    }
    raw_ = create_publisher<mocap_msgs::msg::PixartRawPointArray>(topics::kPixartRaw);
    for (int camera = 0; camera < 4 * settings_.boxes; ++camera) {
      fiducials_.push_back(create_publisher<mocap_msgs::msg::FiducialArray>(
          topics::member_of(topics::kPixartFiducials, camera_name(camera))));
    }
    // A log must exist now, and an adaptor's settings must be usable: a typo is an error at
    // start, not a retry loop.
    if (settings_.source == "candump") source_ = open();
    if (auto problem = settings_.slcan.problem(); settings_.source == "slcan" && problem) {
      throw std::invalid_argument("SlcanSourceOptions::" + *problem);
    }
    // Reading starts with the graph (once the host has started every component), so no frame
    // is published before the subscribers exist.
    create_worker("reader", [this](std::stop_token stop) { read_loop(stop); });
  }

  ~PixartBridge() override {
    const PixartDecodeStats& s = decoder_.stats();
    log().info(
        "{} frames, {} points; {} frames of the wrong length, {} of unknown IDs, {} invalid "
        "points, {} incomplete samples, {} read errors",
        s.frames, s.points, s.wrong_length, s.unknown_id, s.invalid_points,
        assembler_.incomplete_samples(), read_errors_);
  }

 private:
  bool subscribed() const {
    if (raw_.matched_subscribers() > 0) return true;
    for (const auto& publisher : fiducials_) {
      if (publisher.matched_subscribers() > 0) return true;
    }
    return false;
  }

  std::string camera_name(int camera) const {
    if (camera < static_cast<int>(settings_.camera_names.size())) {
      return settings_.camera_names[camera];
    }
    return "camera" + std::to_string(camera);
  }

  std::unique_ptr<can::CanSource> open() {
    if (settings_.source == "slcan") {
      return can::open_slcan(settings_.slcan);
    }
    if (settings_.source == "socketcan") return can::open_socketcan(settings_.interface);
    return can::open_candump(settings_.candump);
  }

  // Reads until stopped; a device that fails is reopened with back-off (0.1 s doubling to
  // 2 s), so unplugging the adaptor costs the frames of the gap and nothing else.
  void read_loop(const std::stop_token& stop) {
    // A log replayed as fast as possible would be over before subscribers in other processes
    // are discovered: it waits for one.
    while (settings_.source == "candump" && !subscribed()) {
      if (!wait_for_stop(stop, std::chrono::milliseconds(10))) return;
    }
    std::chrono::milliseconds backoff(100);
    bool reported_end = false;
    while (!stop.stop_requested()) {
      try {
        if (!source_) {
          source_ = open();
          log().info("reading {}", source_->description());
          backoff = std::chrono::milliseconds(100);
        }
        handle(source_->read(std::chrono::milliseconds(100)));
        if (source_->finished() && !reported_end) {
          for (const CameraSample& sample : assembler_.flush()) publish(sample);
          log().info("end of {}", source_->description());
          reported_end = true;
        }
      } catch (const std::exception& e) {
        if (source_) read_errors_ += source_->read_errors();
        source_.reset();
        log().warn("{}; retrying in {} ms", e.what(), backoff.count());
        wait_for_stop(stop, backoff);
        backoff = std::min(backoff * 2, std::chrono::milliseconds(2000));
      }
    }
    if (source_) read_errors_ += source_->read_errors();
  }

  void handle(const std::vector<can::CanFrame>& frames) {
    if (frames.empty()) return;
    auto raw = std::make_shared<mocap_msgs::msg::PixartRawPointArray>();
    raw->header().stamp(to_time_msg(now()));
    raw->header().frame_id("pixart");
    std::vector<PixartPoint> points;
    for (const can::CanFrame& frame : frames) {
      points.clear();
      auto camera = decoder_.decode(frame, points);
      if (!camera) continue;
      for (const PixartPoint& p : points) {
        mocap_msgs::msg::PixartRawPoint point;
        point.x(p.x);
        point.y(p.y);
        point.camera_id(p.camera_id);
        point.point_id(p.point_id);
        point.stamp(to_time_msg(Clock::time_point(std::chrono::nanoseconds(p.stamp_ns))));
        raw->points().push_back(point);
      }
      int half = static_cast<int>((frame.id - decoder_.options().base_id) & 1u);
      if (auto sample = assembler_.add(*camera, half, frame.stamp_ns, points)) publish(*sample);
    }
    if (!raw->points().empty()) raw_.publish(std::move(raw));
  }

  void publish(const CameraSample& sample) {
    if (sample.camera_id >= fiducials_.size()) return;
    auto array = std::make_shared<mocap_msgs::msg::FiducialArray>();
    array->header().stamp(
        to_time_msg(Clock::time_point(std::chrono::nanoseconds(sample.stamp_ns))));
    array->header().frame_id(camera_name(sample.camera_id));
    for (const PixartPoint& p : sample.points) {
      mocap_msgs::msg::Fiducial fiducial;
      fiducial.x(p.x);
      fiducial.y(p.y);
      fiducial.uncertainty(kQuantisationPx);
      array->fiducials().push_back(fiducial);
    }
    fiducials_[sample.camera_id].publish(std::move(array));
  }

  PixartDecoder decoder_;
  CameraSampleAssembler assembler_;
  std::unique_ptr<can::CanSource> source_;
  Publisher<mocap_msgs::msg::PixartRawPointArray> raw_;
  std::vector<Publisher<mocap_msgs::msg::FiducialArray>> fiducials_;
  uint64_t read_errors_ = 0;
};

}  // namespace
}  // namespace mocap::pixart

MOCAP_REGISTER_COMPONENT(mocap::pixart::PixartBridge, "pixart_bridge")
