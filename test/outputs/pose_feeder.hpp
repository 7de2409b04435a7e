// A component that publishes the /mocap/poses a test hands it: the constellation tracker's
// output, for the plugins that read it.
#pragma once

#include <mocap/component.hpp>
#include <mocap/component_spec.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>

namespace mocap::test {

class PoseFeeder final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.publishes<mocap_msgs::msg::ConstellationPoseArray>("/mocap/poses", Qos::reliable(), "");
  }
  explicit PoseFeeder(Context& context) : Component(context) {
    publisher = create_publisher<mocap_msgs::msg::ConstellationPoseArray>("/mocap/poses");
  }
  Publisher<mocap_msgs::msg::ConstellationPoseArray> publisher;
};

}  // namespace mocap::test
