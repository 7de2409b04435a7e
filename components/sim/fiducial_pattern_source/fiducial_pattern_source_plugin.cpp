// fiducial_pattern_source: publishes a synthetic FiducialArray stream
// (fiducial_pattern_source.hpp).
#include <chrono>

#include <mocap/component.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>

#include "common/topics/graph_topics.hpp"
#include "sim/fiducial_pattern_source/fiducial_pattern_source.hpp"

namespace mocap::demo {
namespace {

// The pattern's options with what only the plugin reads.
struct Settings : PatternOptions {
  double rate_hz = 100;
  std::string frame_id = "camera";
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("rate_hz", "arrays published per second", &Settings::rate_hz)
        .range(0.1, 100000)
        .add("points", "fiducials per array", &Settings::count)
        .range(1, 100000)
        .add("radius_px", "radius of the circle, pixels", &Settings::radius_px)
        .range(0, 10000)
        .add("turns_per_second", "how fast the circle turns", &Settings::turns_per_second)
        .range(-100, 100)
        .add("frame_id", "frame id of the arrays' headers", &Settings::frame_id);

class FiducialPatternSource final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description("Publishes fiducials on a turning circle, a stand-in for a tracked target.");
    kParameters.declare(spec);
    spec.publishes<mocap_msgs::msg::FiducialArray>(topics::kDemoFiducials, Qos::sensor_data(),
                                                   "one array per tick, stamped when made");
  }

  explicit FiducialPatternSource(Context& context) : Component(context) {
    publisher_ = create_publisher<mocap_msgs::msg::FiducialArray>(topics::kDemoFiducials);
    auto period = std::chrono::duration<double>(1.0 / settings_.rate_hz);
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(period), [this] { tick(); });
    log().info("publishing {} fiducials at {} Hz on {}", settings_.count, settings_.rate_hz,
               publisher_.topic());
  }

 private:
  void tick() {
    Clock::time_point now = this->now();
    double t = std::chrono::duration<double>(now - start_).count();
    auto message = std::make_shared<mocap_msgs::msg::FiducialArray>();
    message->header().stamp(to_time_msg(now));
    message->header().frame_id(settings_.frame_id);
    for (const PatternPoint& point : fiducial_pattern(settings_, t)) {
      mocap_msgs::msg::Fiducial fiducial;
      fiducial.x(static_cast<float>(point.x));
      fiducial.y(static_cast<float>(point.y));
      fiducial.size(12.0f);
      fiducial.uncertainty(0.1f);
      message->fiducials().push_back(fiducial);
    }
    publisher_.publish(std::move(message));
  }

  Clock::time_point start_ = Clock::now();
  Publisher<mocap_msgs::msg::FiducialArray> publisher_;
};

}  // namespace
}  // namespace mocap::demo

MOCAP_REGISTER_COMPONENT(mocap::demo::FiducialPatternSource, "fiducial_pattern_source")
