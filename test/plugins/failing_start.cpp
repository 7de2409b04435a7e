// failing_start (test plugin): a component whose constructor fails, as one whose device is
// missing does.
#include <stdexcept>

#include <mocap/component.hpp>

namespace {

struct Settings {
  std::string device = "/dev/ttyUSB9";
};

const mocap::ParameterList<Settings> kParameters = mocap::ParameterList<Settings>().add(
    "device", "the device that is not there", &Settings::device);

class FailingStart final : public mocap::Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(mocap::ComponentSpec& spec) { kParameters.declare(spec); }
  explicit FailingStart(mocap::Context& context) : Component(context) {
    throw std::runtime_error("cannot open " + settings_.device);
  }
};

}  // namespace

MOCAP_REGISTER_COMPONENT(FailingStart, "failing_start")
