// A fixed name for a pseudo-terminal: a simulator's pty gets a new /dev/pts/N each run, and a
// launch file needs a name it can give the driver (`device: /tmp/mocap_turret_servos`).
#pragma once

#include <filesystem>
#include <string>

namespace mocap::serial {

// A symbolic link `link` -> `target` for as long as the object lives.
class DeviceLink {
 public:
  // Points `link` at `target`, replacing an older symbolic link (from a previous run) in one
  // step, so that a driver opening the link never finds it missing. Throws
  // std::invalid_argument when `link` exists and is not a symbolic link (it is not replaced),
  // std::runtime_error naming the link when it cannot be made.
  DeviceLink(std::filesystem::path link, std::string target);
  // Removes the link, unless another run has taken the name over since.
  ~DeviceLink();
  DeviceLink(const DeviceLink&) = delete;
  DeviceLink& operator=(const DeviceLink&) = delete;

  const std::filesystem::path& path() const { return link_; }

 private:
  std::filesystem::path link_;
  std::string target_;
};

}  // namespace mocap::serial
