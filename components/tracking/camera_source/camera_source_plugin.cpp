// camera_source: publishes mono8 images from a V4L2 camera, a video file or a directory of
// images (camera_source.hpp). A camera's images are stamped with its driver's capture time
// (mid-exposure where the exposure is known); recorded input with the moment it was read.
//
// Frames are read on a thread of the component's own, so a device's blocking grab never holds
// the executor. Recorded input is paced at rate_hz and, by default, waits for its first
// subscriber, so that a short recording is not played to nobody while the graph starts.
#include <atomic>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <mocap/component.hpp>
#include <mocap/message_time.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "common/image_message/image_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "tracking/camera_source/camera_source.hpp"

namespace mocap::capture {
namespace {

struct Settings {
  std::string device;
  std::string file;
  std::string directory;
  double rate_hz = 30.0;
  bool loop = false;
  bool wait_for_subscriber = true;
  std::string frame_id = "camera_ir_optical";
  VideoDeviceOptions device_options;  // the requested frame size
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("device",
             "V4L2 camera: a path (/dev/video0) or an index (0), GREY, Y16 or YUYV; frames come "
             "at the device's rate, stamped with its driver's capture time",
             &Settings::device)
        .add("file", "video file (whatever OpenCV decodes)", &Settings::file)
        .path()
        .add("directory", "directory of png/jpg/bmp/tif/pgm images, read in name order",
             &Settings::directory)
        .path()
        .add("rate_hz", "file and directory: frames published per second; 0 = as fast as possible",
             &Settings::rate_hz)
        .range(0, 1e6)
        .add("loop", "file and directory: start over at the end", &Settings::loop)
        .add("wait_for_subscriber",
             "file and directory: hold the first frame until a subscriber has matched",
             &Settings::wait_for_subscriber)
        .add("frame_id", "frame id of the images", &Settings::frame_id)
        .add("width", "device: requested frame width; 0 = the device's", &Settings::device_options,
             &VideoDeviceOptions::width)
        .min(0)
        .add("height", "device: requested frame height; 0 = the device's",
             &Settings::device_options, &VideoDeviceOptions::height)
        .min(0);

class CameraSource final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Publishes mono8 images from a V4L2 camera, a video file or a directory of images "
        "(colour and 16-bit frames are converted). Set exactly one of device, file and "
        "directory.");
    kParameters.declare(spec);
    spec.publishes<sensor_msgs::msg::Image>(topics::kCameraImage, Qos::sensor_data(),
                                            "mono8 images, stamped when captured");
  }

  explicit CameraSource(Context& context) : Component(context) {
    source_ = open_source();
    wait_for_subscriber_ = settings_.wait_for_subscriber && !source_->is_live();
    publisher_ = create_publisher<sensor_msgs::msg::Image>(topics::kCameraImage);
    if (source_->is_live()) {
      log().info("publishing {} on {} at the device's rate", source_->description(),
                 publisher_.topic());
    } else if (settings_.rate_hz > 0) {
      log().info("publishing {} on {} at {} Hz", source_->description(), publisher_.topic(),
                 settings_.rate_hz);
    } else {
      log().info("publishing {} on {} as fast as possible", source_->description(),
                 publisher_.topic());
    }
    // A device's grab returns within a frame period: the stop is seen that soon.
    create_worker("capture", [this](std::stop_token stop) { capture(stop); });
  }

  ~CameraSource() override {
    log().info("published {} frames; {} dropped by the device", published_.load(),
               dropped_by_device_.load());
  }

  void report_health(HealthReport& report) override {
    latency_.report(report, "capture -> image sent");
    const uint64_t dropped = dropped_by_device_.load();
    report.add("frames dropped by the device", std::to_string(dropped));
    if (dropped > reported_drops_) {
      report.flag(HealthLevel::warn,
                  fmt::format("the device dropped {} frame(s) since the last status: the reader "
                              "or the USB bus cannot keep up",
                              dropped - reported_drops_));
    }
    reported_drops_ = dropped;
  }

 private:
  std::unique_ptr<FrameSource> open_source() {
    const std::string device = settings_.device;
    const std::string file = settings_.file;
    const std::string directory = settings_.directory;
    std::vector<std::string> given;
    if (!device.empty()) given.push_back("device");
    if (!file.empty()) given.push_back("file");
    if (!directory.empty()) given.push_back("directory");
    if (given.size() != 1) {
      std::string list = given.empty() ? "none" : given[0];
      for (size_t i = 1; i < given.size(); ++i) list += " and " + given[i];
      throw std::invalid_argument("set exactly one of device, file and directory (got " + list +
                                  ")");
    }
    const bool loop = settings_.loop;
    if (!device.empty()) {
      return std::make_unique<VideoDeviceSource>(device, settings_.device_options);
    }
    if (!file.empty()) return std::make_unique<VideoFileSource>(file, loop);
    return std::make_unique<ImageDirectorySource>(
        directory, loop, [this](const std::string& warning) { log().warn("{}", warning); });
  }

  void capture(const std::stop_token& stop) {
    using Steady = std::chrono::steady_clock;
    try {
      while (wait_for_subscriber_ && publisher_.matched_subscribers() == 0) {
        if (!wait_for_stop(stop, std::chrono::milliseconds(10))) return;
      }
      const auto period = settings_.rate_hz > 0
                              ? std::chrono::duration_cast<Steady::duration>(
                                    std::chrono::duration<double>(1.0 / settings_.rate_hz))
                              : Steady::duration::zero();
      Steady::time_point next = Steady::now();
      cv::Mat frame;
      while (!stop.stop_requested()) {
        if (!source_->read(frame)) {
          log().info("end of input after {} frames", source_->frames_read());
          return;
        }
        // A camera's own capture time (its driver's), else the moment it was read.
        const Clock::time_point captured = source_->captured().value_or(now());
        auto message = std::make_shared<sensor_msgs::msg::Image>();
        message->header().stamp(to_time_msg(captured));
        message->header().frame_id(settings_.frame_id);
        fill_image_message(frame, *message);
        publisher_.publish(std::move(message));
        latency_.add(now() - captured);
        dropped_by_device_.store(source_->dropped());
        published_.fetch_add(1);
        if (source_->is_live() || period == Steady::duration::zero()) continue;
        // Keep to the rate's grid; after a stall, start a new grid rather than catch up in
        // a burst.
        next += period;
        if (next < Steady::now()) next = Steady::now();
        if (!wait_for_stop(stop, next - Steady::now())) return;
      }
    } catch (const std::exception& e) {
      log().error("{}: {}; no more frames", source_->description(), e.what());
    }
  }

  std::unique_ptr<FrameSource> source_;
  bool wait_for_subscriber_ = true;
  Publisher<sensor_msgs::msg::Image> publisher_;
  std::atomic<uint64_t> published_{0};
  std::atomic<uint64_t> dropped_by_device_{0};
  uint64_t reported_drops_ = 0;  // as of the last status
  LatencyFigures latency_;       // added by the capture worker
};

}  // namespace
}  // namespace mocap::capture

MOCAP_REGISTER_COMPONENT(mocap::capture::CameraSource, "camera_source")
