#include "launch/restart_policy.hpp"

#include <algorithm>

namespace mocap {

std::optional<RestartPolicy::Duration> RestartPolicy::on_death(Time at) {
  deaths_.push_back(at);
  while (!deaths_.empty() && at - deaths_.front() >= options_.window) deaths_.pop_front();
  const int deaths = static_cast<int>(deaths_.size());
  if (deaths >= options_.max_deaths) return std::nullopt;
  return options_.first_delay * (1 << std::min(deaths - 1, 20));
}

int RestartPolicy::deaths_within_window(Time at) const {
  return static_cast<int>(std::count_if(deaths_.begin(), deaths_.end(), [&](Time death) {
    return death <= at && at - death < options_.window;
  }));
}

}  // namespace mocap
