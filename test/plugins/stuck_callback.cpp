// stuck_callback (test plugin): a component whose timer callback never returns, as one waiting
// on a device that never answers: the process's graceful stop hangs on it.
#include <unistd.h>

#include <chrono>

#include <mocap/component.hpp>

namespace {

class StuckCallback final : public mocap::Component {
 public:
  static void declare(mocap::ComponentSpec& spec) {
    spec.description("A timer callback that never returns (tests of forced exits).");
  }
  explicit StuckCallback(mocap::Context& context) : Component(context) {
    create_timer(std::chrono::milliseconds(100), [] {
      for (;;) pause();  // signals interrupt pause(); the loop does not end
    });
  }
};

}  // namespace

MOCAP_REGISTER_COMPONENT(StuckCallback, "stuck_callback")
