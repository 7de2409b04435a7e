// image_sink (test plugin): subscribes to images on the test topic, to provoke a type clash.
#include <mocap/component.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "test/plugins/sequence_message.hpp"

namespace mocap::test {
namespace {

class ImageSink final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<sensor_msgs::msg::Image>(kSequenceTopic, Qos::sensor_data(), "images");
  }
  explicit ImageSink(Context& context) : Component(context) {
    create_subscription<sensor_msgs::msg::Image>(kSequenceTopic,
                                                 [](const sensor_msgs::msg::Image&) {});
  }
};

}  // namespace
}  // namespace mocap::test

MOCAP_REGISTER_COMPONENT(mocap::test::ImageSink, "image_sink")
