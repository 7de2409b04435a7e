// failing_start (test plugin): a component whose constructor fails, as one whose device is
// missing does.
#include <stdexcept>

#include <mocap/component.hpp>

namespace {

class FailingStart final : public mocap::Component {
 public:
  static void declare(mocap::ComponentSpec& spec) {
    spec.parameter("device", "/dev/ttyUSB9", "the device that is not there");
  }
  explicit FailingStart(mocap::Context& context) : Component(context) {
    throw std::runtime_error("cannot open " + param<std::string>("device"));
  }
};

}  // namespace

MOCAP_REGISTER_COMPONENT(FailingStart, "failing_start")
