// The instant a launch started, shared by every process mocap_launch starts for it (and by
// their restarts, which inherit it): simulated sensors in different processes count their
// scene's time from it, so that they show the same instant in frames of the same stamp.
// mocap_launch sets it unless it is set already (launchers on several hosts given one value).
#pragma once

#include <charconv>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string_view>

namespace mocap {

inline constexpr const char* kLaunchStartVariable = "MOCAP_LAUNCH_START_NS";
// Set by mocap_launch for a group it starts again after the group's process died: how many
// times it did, and how the last one ended ("was killed by signal 9"), for its diagnostics.
inline constexpr const char* kGroupRestartsVariable = "MOCAP_GROUP_RESTARTS";
inline constexpr const char* kGroupLastEndVariable = "MOCAP_GROUP_LAST_END";

// nullopt when this process was not started by mocap_launch (or the variable is not a count
// of nanoseconds since the epoch).
inline std::optional<std::chrono::system_clock::time_point> launch_start() {
  const char* text = std::getenv(kLaunchStartVariable);
  if (text == nullptr) return std::nullopt;
  const std::string_view view(text);
  int64_t ns = 0;
  auto [end, error] = std::from_chars(view.data(), view.data() + view.size(), ns);
  if (error != std::errc() || end != view.data() + view.size() || ns <= 0) return std::nullopt;
  return std::chrono::system_clock::time_point(
      std::chrono::duration_cast<std::chrono::system_clock::duration>(
          std::chrono::nanoseconds(ns)));
}

// 0 when this process is its group's first (or was not started by mocap_launch).
inline int group_restarts() {
  const char* text = std::getenv(kGroupRestartsVariable);
  if (text == nullptr) return 0;
  const std::string_view view(text);
  int restarts = 0;
  auto [end, error] = std::from_chars(view.data(), view.data() + view.size(), restarts);
  return error == std::errc() && end == view.data() + view.size() && restarts > 0 ? restarts : 0;
}

}  // namespace mocap
