#include "mocap_launch/launch_alerts.hpp"

#include <chrono>
#include <mutex>
#include <vector>

#include <mocap/component.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/alert.hpp>

namespace mocap {

// A component of the launcher's own host: alerts queued by the supervising thread, published
// on the executor's.
class LaunchAlerts::Publisher final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.description("the launcher's supervisor: groups restarted, given up on or gone");
    // As the volume's deployments give it: a stalled subscriber never holds the launcher up.
    Qos qos = Qos::reliable();
    qos.max_blocking = std::chrono::milliseconds(100);
    spec.publishes<mocap_msgs::msg::Alert>("/alerts", qos, "groups restarted or given up on");
  }
  explicit Publisher(Context& context) : Component(context) {
    alerts_ = create_publisher<mocap_msgs::msg::Alert>("/alerts");
    create_timer(std::chrono::milliseconds(20), [this] { flush(); });
  }
  void queue(const SupervisorEvent& event) {
    mocap_msgs::msg::Alert alert;
    alert.header().stamp(to_time_msg(now()));
    alert.source("launch");
    alert.level(static_cast<uint8_t>(event.level));
    alert.text(event.text);
    std::lock_guard lock(mutex_);
    queued_.push_back(std::move(alert));
  }

 private:
  void flush() {
    std::vector<mocap_msgs::msg::Alert> alerts;
    {
      std::lock_guard lock(mutex_);
      alerts.swap(queued_);
    }
    for (mocap_msgs::msg::Alert& alert : alerts) alerts_.publish(std::move(alert));
  }

  mocap::Publisher<mocap_msgs::msg::Alert> alerts_;
  std::mutex mutex_;
  std::vector<mocap_msgs::msg::Alert> queued_;
};

LaunchAlerts::LaunchAlerts(const DdsOptions& dds) {
  host_ = std::make_unique<ComponentHost>(HostOptions{.name = "launch", .threads = 1, .dds = dds});
  publisher_ = static_cast<Publisher*>(
      &host_->add(make_component_factory<Publisher>("launch_alerts"), {.name = "launch"}));
  host_->start();
}

LaunchAlerts::~LaunchAlerts() = default;

void LaunchAlerts::publish(const SupervisorEvent& event) { publisher_->queue(event); }

}  // namespace mocap
