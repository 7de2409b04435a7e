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

std::vector<size_t> frames_to_fuse(const std::vector<int64_t>& stamps_ns,
                                   std::optional<int64_t> last_fused_ns, size_t newest,
                                   int64_t max_gap_ns) {
  std::vector<size_t> fused;
  const size_t count = stamps_ns.size();
  for (size_t i = 0; i < count; ++i) {
    // Frame i is fused when it is among the newest, or when leaving it out would put the next
    // frame further than the gap from the one fused before.
    const bool needed =
        i + newest >= count || (last_fused_ns && stamps_ns[i + 1] - *last_fused_ns > max_gap_ns);
    if (!needed) continue;
    fused.push_back(i);
    last_fused_ns = stamps_ns[i];
  }
  return fused;
}

}  // namespace mocap::volume
