// When a group that died is started again, and when it is given up on: ROS 2 launch's
// `respawn` and `respawn_delay`, with a back-off and a limit.
#pragma once

#include <chrono>
#include <deque>
#include <optional>

namespace mocap {

struct RestartPolicyOptions {
  // The wait before the first restart; each death within `window` doubles it. Short, because a
  // motion-capture volume fuses the other cameras meanwhile and wants the camera back soon.
  std::chrono::milliseconds first_delay{250};
  // A group that dies this many times within `window` is given up on.
  int max_deaths = 5;
  std::chrono::seconds window{60};
};

class RestartPolicy {
 public:
  using Time = std::chrono::steady_clock::time_point;
  using Duration = std::chrono::steady_clock::duration;

  explicit RestartPolicy(RestartPolicyOptions options = {}) : options_(options) {}

  // A death at `at`: the wait before the restart, or nullopt when this is the max_deaths-th
  // death within the window (give the group up).
  std::optional<Duration> on_death(Time at);
  // Deaths within the window before `at`, the one at `at` included when recorded.
  int deaths_within_window(Time at) const;
  const RestartPolicyOptions& options() const { return options_; }

 private:
  RestartPolicyOptions options_;
  std::deque<Time> deaths_;
};

}  // namespace mocap
