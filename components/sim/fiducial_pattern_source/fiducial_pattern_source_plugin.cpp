// fiducial_pattern_source: publishes a synthetic FiducialArray stream (fiducial_pattern.hpp).
#include <chrono>

#include <mocap/component.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>

#include "fiducial_pattern.hpp"

namespace mocap::demo {
namespace {

constexpr const char* kTopic = "/demo/fiducials";

class FiducialPatternSource final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.description("Publishes fiducials on a turning circle, a stand-in for a tracked target.");
    spec.parameter("rate_hz", 100.0, "arrays published per second").range(0.1, 100000);
    spec.parameter("points", 12, "fiducials per array").range(1, 100000);
    spec.parameter("radius_px", 200.0, "radius of the circle, pixels").range(0, 10000);
    spec.parameter("turns_per_second", 0.1, "how fast the circle turns").range(-100, 100);
    spec.parameter("frame_id", std::string("camera"), "frame id of the arrays' headers");
    spec.publishes<mocap_msgs::msg::FiducialArray>(kTopic, Qos::sensor_data(),
                                                   "one array per tick, stamped when made");
  }

  explicit FiducialPatternSource(Context& context) : Component(context) {
    options_.count = param<int>("points");
    options_.radius_px = param<double>("radius_px");
    options_.turns_per_second = param<double>("turns_per_second");
    frame_id_ = param<std::string>("frame_id");
    publisher_ = create_publisher<mocap_msgs::msg::FiducialArray>(kTopic);
    auto period = std::chrono::duration<double>(1.0 / param<double>("rate_hz"));
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(period), [this] { tick(); });
    log().info("publishing {} fiducials at {} Hz on {}", options_.count, param<double>("rate_hz"),
               publisher_.topic());
  }

 private:
  void tick() {
    Clock::time_point now = this->now();
    double t = std::chrono::duration<double>(now - start_).count();
    auto message = std::make_shared<mocap_msgs::msg::FiducialArray>();
    message->header().stamp(to_time_msg(now));
    message->header().frame_id(frame_id_);
    for (const PatternPoint& point : fiducial_pattern(options_, t)) {
      mocap_msgs::msg::Fiducial fiducial;
      fiducial.x(static_cast<float>(point.x));
      fiducial.y(static_cast<float>(point.y));
      fiducial.size(12.0f);
      fiducial.uncertainty(0.1f);
      message->fiducials().push_back(fiducial);
    }
    publisher_.publish(std::move(message));
  }

  PatternOptions options_;
  std::string frame_id_;
  Clock::time_point start_ = Clock::now();
  Publisher<mocap_msgs::msg::FiducialArray> publisher_;
};

}  // namespace
}  // namespace mocap::demo

MOCAP_REGISTER_COMPONENT(mocap::demo::FiducialPatternSource, "fiducial_pattern_source")
