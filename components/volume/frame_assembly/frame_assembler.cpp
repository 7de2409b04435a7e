#include "volume/frame_assembly/frame_assembler.hpp"

#include <fmt/format.h>

namespace mocap::volume {
namespace {

double milliseconds(std::chrono::nanoseconds duration) {
  return std::chrono::duration<double, std::milli>(duration).count();
}

}  // namespace

std::optional<std::string> FrameAssemblerOptions::problem() const {
  // Negative, no two stamps would be one capture time: every message a frame of its own.
  if (same_capture.count() < 0) {
    return fmt::format("same_capture: {} ms is below 0", milliseconds(same_capture));
  }
  if (wait.count() < 0) return fmt::format("wait: {} ms is below 0", milliseconds(wait));
  if (!(wait_share_of_frame >= 0 && wait_share_of_frame <= 1)) {
    return fmt::format("wait_share_of_frame: {} is not between 0 and 1", wait_share_of_frame);
  }
  // Not above 0, every camera would count as silent, and every frame as complete.
  if (silent_after.count() <= 0) {
    return fmt::format("silent_after: {} ms is not above 0", milliseconds(silent_after));
  }
  return std::nullopt;
}

}  // namespace mocap::volume
