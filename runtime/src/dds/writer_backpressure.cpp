#include "dds/writer_backpressure.hpp"

#include <fmt/format.h>

#include "core/shutdown_signal.hpp"

namespace mocap {

std::optional<std::string> WriterBackpressure::reason_to_give_up(
    std::chrono::steady_clock::time_point start) const {
  if (stopped_waiting_.load()) {
    return fmt::format("the process is stopping and {} had no room", subscribers_());
  }
  if (endpoint_.qos.max_blocking &&
      std::chrono::steady_clock::now() - start >= *endpoint_.qos.max_blocking) {
    return fmt::format("{} had no room for max_blocking {} ms", subscribers_(),
                       endpoint_.qos.max_blocking->count());
  }
  return std::nullopt;
}

std::optional<std::string> WriterBackpressure::reason_to_stop_delivering(
    std::chrono::steady_clock::time_point start) const {
  if (ShutdownSignal::received()) return "the process is stopping";
  if (std::chrono::steady_clock::now() - start >= kCloseWait) {
    return fmt::format("waited {} s", kCloseWait.count());
  }
  return std::nullopt;
}

}  // namespace mocap
