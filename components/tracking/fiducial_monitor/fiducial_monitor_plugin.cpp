// fiducial_monitor: reports the rate, size and latency of a FiducialArray stream.
#include <chrono>

#include <mocap/component.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>

#include "common/topics/graph_topics.hpp"
#include "tracking/fiducial_monitor/fiducial_monitor.hpp"

namespace mocap::demo {
namespace {

struct Settings {
  double report_period_s = 2;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("report_period_s", "seconds between reports", &Settings::report_period_s)
        .range(0.1, 3600);

class FiducialMonitor final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description("Logs the rate, size and latency (stamp to arrival) of fiducial arrays.");
    kParameters.declare(spec);
    spec.subscribes<mocap_msgs::msg::FiducialArray>(topics::kDemoFiducials, Qos::sensor_data(),
                                                    "the stream to watch");
  }

  explicit FiducialMonitor(Context& context) : Component(context) {
    create_subscription<mocap_msgs::msg::FiducialArray>(
        topics::kDemoFiducials, [this](const mocap_msgs::msg::FiducialArray& array) {
          double latency =
              std::chrono::duration<double>(now() - from_time_msg(array.header().stamp())).count();
          statistics_.add(latency, array.fiducials().size());
        });
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(settings_.report_period_s)),
                 [this] { report(); });
  }

  ~FiducialMonitor() override {
    log().info("received {} arrays in all", statistics_.total_messages());
  }

 private:
  void report() {
    auto r = statistics_.report();
    if (!r) {
      log().info("nothing received in the last {} s", settings_.report_period_s);
      return;
    }
    log().info(
        "{} arrays ({:.1f}/s), {:.1f} fiducials each, latency median {:.3f} ms, "
        "p99 {:.3f} ms, max {:.3f} ms",
        r->messages, static_cast<double>(r->messages) / settings_.report_period_s, r->mean_items,
        r->latency_median_s * 1e3, r->latency_p99_s * 1e3, r->latency_max_s * 1e3);
  }

  StreamStatistics statistics_;
};

}  // namespace
}  // namespace mocap::demo

MOCAP_REGISTER_COMPONENT(mocap::demo::FiducialMonitor, "fiducial_monitor")
